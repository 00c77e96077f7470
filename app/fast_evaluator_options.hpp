#pragma once
// The --fast-* options of train, upgrade and calibrate: what a model's fast evaluator is built to,
// within which work budget, and the one policy that keeps it (surrogate/fast/fast_evaluator_build.hpp,
// short_grid_refusal), with the lines that report it.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/fast/fast_evaluator.hpp"
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric::app {

struct FastOptions {
  FastEvaluatorOptions build;
  double max_gigawork = 0.0;  // 10⁹ multiply-adds; 0: the default (100 n³ for a GP of n points, at least kLeastFastEvaluatorWork)
  bool skip = false;          // --no-fast-evaluator
};

void add_fast_evaluator_options(CLI::App* cmd, FastOptions& o);

// Builds and reports a fast evaluator of `source` (`label` names it in the messages: "model", "patch
// scatter", "calibrated model"); null when it does not come within short_grid_refusal's factor of the
// tolerances. The message says what stopped it and how to build it later.
std::shared_ptr<const FastEvaluator> build_fast_evaluator(const GridSource& source, FastEvaluatorOptions build,
                                                          const std::string& label);

// The GP's fast evaluator and, for a model with a patch scatter, the scatter's: its log variance
// tabulated to the tolerance that holds patch_std to --fast-std-tolerance (relative), its own σ unused.
// Any grid the model had is dropped first (never a grid of another fit or range); --no-fast-evaluator
// leaves none.
void attach_fast_evaluator(GaussianProcess& gp, const FastOptions& o);
// The calibrated model's, certified against its exact posterior predictive.
void attach_fast_evaluator(CalibratedModel& model, const FastOptions& o);

}  // namespace mufric::app
