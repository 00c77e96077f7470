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
#include "surrogate/fast/tensor_cubic_grid.hpp"

namespace mufric {

struct FastEvaluatorOptions;
struct GridSource;

struct FastEvaluatorBounds {
  double mu_absolute = std::numeric_limits<double>::infinity();   // max |μ_fast − μ|
  double std_relative = std::numeric_limits<double>::infinity();  // max |σ_fast − σ| / max(σ, std_floor)
  // μ units; 0 in files written before it (a purely relative bound then).
  double std_floor = 0.0;
};

class FastEvaluator {
 public:
  // Measured error × this is the stored bound: the check set samples the error field, it does not
  // visit every cell.
  static constexpr double kBoundSafetyFactor = 2.0;

  FastEvaluator(InputSpace box, TensorCubicGrid grid, FastEvaluatorBounds bounds);

  // Why build_fast_evaluator stopped, for the caller's message: "" when it met the tolerances.
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
  // The builder (surrogate/fast/fast_evaluator_build.hpp) sets the certified bounds and the stop reason.
  friend FastEvaluator build_fast_evaluator(const GridSource& source, const FastEvaluatorOptions& options);

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

}  // namespace mufric
