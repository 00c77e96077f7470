#pragma once
// Building and certifying a FastEvaluator (surrogate/fast/fast_evaluator.hpp) from any smooth model
// (a Gaussian process's grids: surrogate/gp/gp_grids.hpp; a calibrated model's): the tolerances and
// budgets, the refinement loop and the error measurement against the exact model. Apart from the
// evaluator itself so that a model that evaluates through a grid does not depend on the code that
// builds one.
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include "common/error.hpp"
#include "surrogate/fast/fast_evaluator.hpp"
#include "surrogate/core/friction_model.hpp"

namespace mufric {

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


// What a grid is built from: a model evaluated exactly (EvaluationRequest with zero tolerances), the
// length scale along each input in widths of its box (the grid's cells per input ∝ 1/ℓ), and the
// multiply-adds of one exact evaluation of μ and σ (the unit of the work budget).
struct GridSource {
  const FrictionModel& model;
  Eigen::VectorXd unit_length_scales;
  double point_work = 0.0;
};

// Refines until the bounds are within the options' tolerances, or the next grid would exceed the
// memory cap or the work budget (then the finest grid built, whose bounds say what it reached).
FastEvaluator build_fast_evaluator(const GridSource& source, const FastEvaluatorOptions& options);


// One policy for a grid that stops short of its tolerances (train, upgrade and calibrate alike): it is
// kept with the bound it certified when that bound is within this factor of each tolerance asked —
// requests that ask no more than the bound use it (the C ABI's std_tolerance=2e-3, say), the others
// the exact model — and dropped otherwise: a grid no request would use only weighs on the file
// (issue 30: 57.7 MB for a 2-point model).
inline constexpr double kShortGridUsefulFactor = 10.0;
// "" when `fast` is worth storing (it meets the options' tolerances, or comes within the factor);
// else why not, with the bounds it reached.
std::string short_grid_refusal(const FastEvaluator& fast, const FastEvaluatorOptions& options);

// Builds one grid and says whether it is kept (null: over the memory cap, or refused by
// short_grid_refusal); `label` names it ("model", "patch scatter"). The app's prints what it does.
using GridBuilder = std::function<std::shared_ptr<const FastEvaluator>(const GridSource& source,
                                                                       const FastEvaluatorOptions& options,
                                                                       const std::string& label)>;
// The same, quiet: for a library caller that reports the outcome itself (the learner).
std::shared_ptr<const FastEvaluator> build_kept_fast_evaluator(const GridSource& source, const FastEvaluatorOptions& options,
                                                                const std::string& label);

// The largest errors of `fast` against the exact `model` at the points x (SI, one row each): what
// the bound is measured from, and what a test checks it with.
FastEvaluatorBounds measure_errors(const FastEvaluator& fast, const FrictionModel& model, const Eigen::MatrixXd& x);

}  // namespace mufric
