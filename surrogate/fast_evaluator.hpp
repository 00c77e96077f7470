#pragma once
// A certified fast evaluator of a Gaussian process: the posterior mean μ and log σ tabulated on a
// tensor grid over the model's box and interpolated piecewise-cubically (TensorCubicGrid), with an
// error bound measured against the exact GP — on a random check set independent of the grid plus
// local searches for the worst error from its worst points — times a safety factor. The grid is
// refined (cells per input ∝ 1/length scale) until the bound is within the tolerances or the
// memory cap stops it; the bound actually reached is kept either way, so a caller uses the grid
// only where the bound serves the request.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "common/input_space.hpp"
#include "surrogate/gaussian_process.hpp"
#include "surrogate/tensor_cubic_grid.hpp"

namespace mufric {

struct FastEvaluatorBounds {
  double mu_absolute = std::numeric_limits<double>::infinity();   // max |μ_fast − μ|
  double std_relative = std::numeric_limits<double>::infinity();  // max |σ_fast − σ| / σ
};

struct FastEvaluatorOptions {
  double mu_tolerance = 1e-6;            // absolute, μ units
  double std_relative_tolerance = 1e-3;  // the interval's half-width to 0.1 %
  long long check_points = 20000;        // random points per measurement
  int local_searches = 16;               // from the worst check points, at the final grid
  double max_megabytes = 64.0;           // the grid's node values
  unsigned seed = 1;
  std::function<void(const std::string&)> progress;  // one line per refinement; may be empty
};

class FastEvaluator {
 public:
  // Measured error × this is the stored bound: the check set samples the error field, it does not
  // visit every cell.
  static constexpr double kBoundSafetyFactor = 2.0;

  FastEvaluator(InputSpace box, TensorCubicGrid grid, FastEvaluatorBounds bounds);

  // Refines until the bounds are within the options' tolerances, or the next grid would exceed the
  // memory cap (then the finest grid within it, whose bounds say what it reached).
  static FastEvaluator build(const GaussianProcess& gp, const FastEvaluatorOptions& options);

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
  Eigen::VectorXd lo_, inverse_width_;
};

// log σ is tabulated; σ below this (no noise term, at a training point) cannot be.
inline constexpr double kSmallestTabulatedStd = 1e-300;
inline double tabulated_log_std(double std) { return std::log(std::max(std, kSmallestTabulatedStd)); }

// The largest errors of `fast` against the exact `gp` at the points x (SI, one row each): what the
// bound is measured from, and what a test checks it with.
FastEvaluatorBounds measure_errors(const FastEvaluator& fast, const GaussianProcess& gp, const Eigen::MatrixXd& x);

}  // namespace mufric
