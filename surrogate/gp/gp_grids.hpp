#pragma once
// A Gaussian process's grids: the GP as a FastEvaluator's source (its length scales and the cost of
// one exact point), the default work budget of its grid, and the grids it serves with (its own and
// its patch scatter's). The builder itself, for any smooth model, is surrogate/fast/fast_evaluator_build.hpp.
#include "surrogate/fast/fast_evaluator_build.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// Multiply-adds of one exact evaluation of μ and σ, the unit of FastEvaluatorOptions::max_work:
// n(n + d) for a GP of n training points in d inputs (k* is n·d, σ's triangular solve n²). About
// 1e10 per second on one core of a 2-core AMD EPYC with AVX2 (bench/studies/calibration/README.md).
double exact_point_work(const GaussianProcess& gp);

// The GP as a grid's source: its length scales and exact_point_work.
GridSource grid_source(const GaussianProcess& gp);
// The GP's own grid (grid_source(gp)).
FastEvaluator build_fast_evaluator(const GaussianProcess& gp, const FastEvaluatorOptions& options);

// The default work budget of a GP's grid (FastEvaluatorOptions::max_work), counted in work, never in
// seconds: a model file must not depend on how busy the machine was (issue 49: a 900-point model was
// written without its grid on a loaded machine, with it on an idle one). A grid pays off in
// proportion to the exact model's cost per point, which grows with n as the fit's does: the budget is
// about what a fit of n points costs, ~100 likelihood evaluations of ~n³ each, and at least
// kLeastFastEvaluatorWork: a wavy noise-free 900-point model certifies its σ (the wells at its
// training points) only at 1.7e12 (issue 63: at the earlier 1e11 it stored none and answered at the
// exact GP's 35 µs a point instead of 0.3; bench/studies/fast_evaluator/README.md, "The fast evaluator's default budget").
inline constexpr double kLeastFastEvaluatorWork = 3e12;
inline constexpr double kFitLikeEvaluations = 100.0;
double default_fast_evaluator_work(Eigen::Index training_points);

// The grids a GP serves with: its own and, with a patch scatter, the scatter's log variance tabulated
// to the tolerance that holds patch_std to options.std_relative_tolerance (its own σ unused). Any grid
// the model had is dropped first, never a grid of another fit or range; options.max_work of 0 or
// less means default_fast_evaluator_work of the GP's points.
void attach_fast_evaluators(GaussianProcess& gp, FastEvaluatorOptions options, const GridBuilder& build);

}  // namespace mufric
