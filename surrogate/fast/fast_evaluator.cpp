#include "surrogate/fast/fast_evaluator.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"
#include "surrogate/core/vector_exp.hpp"

namespace mufric {

FastEvaluator::FastEvaluator(InputSpace box, TensorCubicGrid grid, FastEvaluatorBounds bounds)
    : box_(std::move(box)), grid_(std::move(grid)), bounds_(bounds) {
  if (static_cast<int>(box_.size()) != grid_.inputs() || grid_.outputs() != 2) {
    throw Error("fast evaluator: a grid of " + std::to_string(grid_.inputs()) + " inputs and " +
                std::to_string(grid_.outputs()) + " outputs for a box of " + std::to_string(box_.size()) +
                " inputs (expected 2 outputs: mu, log std)");
  }
  if (!(bounds_.mu_absolute >= 0.0) || !(bounds_.std_relative >= 0.0) || !(bounds_.std_floor >= 0.0) ||
      !std::isfinite(bounds_.std_floor)) {
    throw Error("fast evaluator: error bounds and the std floor must be >= 0");
  }
  const auto d = static_cast<Eigen::Index>(box_.size());
  lo_.resize(d);
  inverse_width_.resize(d);
  for (Eigen::Index k = 0; k < d; ++k) {
    lo_(k) = box_[static_cast<size_t>(k)].lo;
    inverse_width_(k) = 1.0 / (box_[static_cast<size_t>(k)].hi - box_[static_cast<size_t>(k)].lo);
  }
}

bool FastEvaluator::inside(const double* x) const {
  for (size_t k = 0; k < box_.size(); ++k) {
    if (!box_[k].contains(x[k])) return false;
  }
  return true;
}

void FastEvaluator::evaluate(const double* x, double& mu, double& std) const {
  double u[TensorCubicGrid::kMaximumInputs];
  const auto d = static_cast<Eigen::Index>(box_.size());
  for (Eigen::Index k = 0; k < d; ++k) u[k] = (x[k] - lo_(k)) * inverse_width_(k);
  double out[2];
  grid_.evaluate(u, out);
  mu = out[0];
  std = out[1];
  exp_in_place(&std, 1);  // the batch's vector exp: the same σ alone or in a batch, to the bit
}

void FastEvaluator::evaluate(const Eigen::MatrixXd& x, double* mu, double* std) const {
  const Eigen::Index d = x.cols();
  double u[TensorCubicGrid::kMaximumInputs];
  double out[2];
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    for (Eigen::Index k = 0; k < d; ++k) u[k] = (x(i, k) - lo_(k)) * inverse_width_(k);
    grid_.evaluate(u, out);
    mu[i] = out[0];
    std[i] = out[1];
  }
  exp_in_place(std, x.rows());  // σ from log σ, vectorised over the batch
}

}  // namespace mufric
