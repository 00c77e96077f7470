#pragma once
// A certified fast evaluator of a Gaussian process: the posterior mean μ and log σ tabulated on a
// tensor grid over the model's box and interpolated piecewise-cubically (TensorCubicGrid), with an
// error bound measured against the exact GP — on a random check set independent of the grid plus
// local searches for the worst error from its worst points — times a safety factor. The grid is
// refined (cells per input ∝ 1/length scale) until the bound is within the tolerances, or until the
// next grid would break the memory or work budget (both predicted before it is built); the bound
// actually reached is kept either way, so a caller uses the grid only where the bound serves the
// request.
//
// What σ's tolerance means. σ is held to R of itself (R = std_relative_tolerance), but never to
// less than the absolute accuracy of μ: the interval's bounds μ ± zσ cannot be more accurate than μ
// itself, so σ's error is measured against max(σ, σ_floor) with σ_floor = mu_tolerance / R (1e-3 in
// μ units at the defaults). With a noise-free model σ sits at the noise floor (1e-4 of μ) with a
// well at every training point, and a purely relative tolerance asked the grid to resolve wells whose
// depth no interval can show (issue 30: 51.6 MB and 158 s for 900 points).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "common/error.hpp"
#include "common/input_space.hpp"
#include "surrogate/gaussian_process.hpp"
#include "surrogate/tensor_cubic_grid.hpp"

namespace mufric {

struct FastEvaluatorBounds {
  double mu_absolute = std::numeric_limits<double>::infinity();   // max |μ_fast − μ|
  double std_relative = std::numeric_limits<double>::infinity();  // max |σ_fast − σ| / max(σ, std_floor)
  // μ units; 0 in files written before it (a purely relative bound then).
  double std_floor = 0.0;
};

// Even the coarsest grid would exceed FastEvaluatorOptions::max_megabytes: no fast evaluator can be
// built within the cap, and the exact model is the answer (train stores the model without one).
class FastEvaluatorOverCap : public Error {
 public:
  using Error::Error;
};

struct FastEvaluatorOptions {
  double mu_tolerance = 1e-6;            // absolute, μ units
  double std_relative_tolerance = 1e-3;  // the interval's half-width to 0.1 %
  // Random points of the final certification (refinement rounds use fewer). 5000 with the local
  // searches and the safety factor held on 10⁶ fresh points (FastEvaluator.TheMeasuredBoundHoldsOnFreshPoints).
  long long check_points = 5000;
  int local_searches = 16;               // from the worst check points, at the final grid
  double max_megabytes = 64.0;           // the grid's node values
  // Work budget of the whole build, refinements and certification, in multiply-adds of the exact
  // model (exact_point_work per point evaluated): a finer grid whose nodes and checks would take the
  // work done past it is not built. Counted, not timed, so that the same model and options give the
  // same grid on a busy machine and an idle one. `train` sets it from the GP fit's own work.
  double max_work = std::numeric_limits<double>::infinity();
  unsigned seed = 1;
  std::function<void(const std::string&)> progress;  // one line per refinement; may be empty
};

// Multiply-adds of one exact evaluation of μ and σ, the unit of FastEvaluatorOptions::max_work:
// n(n + d) for a GP of n training points in d inputs (k* is n·d, σ's triangular solve n²). About
// 1e10 per second on one core of a 2-core AMD EPYC with AVX2 (bench/RESULTS.md).
double exact_point_work(const GaussianProcess& gp);

class FastEvaluator {
 public:
  // Measured error × this is the stored bound: the check set samples the error field, it does not
  // visit every cell.
  static constexpr double kBoundSafetyFactor = 2.0;

  FastEvaluator(InputSpace box, TensorCubicGrid grid, FastEvaluatorBounds bounds);

  // Refines until the bounds are within the options' tolerances, or the next grid would exceed the
  // memory cap or the work budget (then the finest grid built, whose bounds say what it reached).
  static FastEvaluator build(const GaussianProcess& gp, const FastEvaluatorOptions& options);
  // Why build() stopped, for the caller's message: "" when it met the tolerances.
  const std::string& stop_reason() const { return stop_reason_; }

  // μ and σ at x (SI, d inputs); x must be inside the box (inside()).
  void evaluate(const double* x, double& mu, double& std) const;
  // Every row of x (SI, inside the box): mu[i], std[i].
  void evaluate(const Eigen::MatrixXd& x, double* mu, double* std) const;
  bool inside(const double* x) const;
  bool meets(double mu_tolerance, double std_relative_tolerance) const {
    return bounds_.mu_absolute <= mu_tolerance && bounds_.std_relative <= std_relative_tolerance;
  }

  const FastEvaluatorBounds& bounds() const { return bounds_; }
  const TensorCubicGrid& grid() const { return grid_; }
  const InputSpace& box() const { return box_; }

 private:
  InputSpace box_;
  TensorCubicGrid grid_;
  FastEvaluatorBounds bounds_;
  std::string stop_reason_;
  Eigen::VectorXd lo_, inverse_width_;
};

// log σ is tabulated; σ below this (no noise term, at a training point) cannot be.
inline constexpr double kSmallestTabulatedStd = 1e-300;
inline double tabulated_log_std(double std) { return std::log(std::max(std, kSmallestTabulatedStd)); }

// σ below which its error is measured absolutely (see the header comment).
inline double std_floor_for(double mu_tolerance, double std_relative_tolerance) {
  return mu_tolerance / std_relative_tolerance;
}

// The largest errors of `fast` against the exact `gp` at the points x (SI, one row each): what the
// bound is measured from, and what a test checks it with.
FastEvaluatorBounds measure_errors(const FastEvaluator& fast, const GaussianProcess& gp, const Eigen::MatrixXd& x);

}  // namespace mufric
