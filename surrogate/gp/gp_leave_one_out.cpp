#include "surrogate/gp/gp_training.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/error.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/core/cholesky.hpp"

// Exact leave-one-out predictions of a fitted GP in closed form (R&W eq. 5.12) and the accuracy figures
// `train` prints from them.
namespace mufric {
namespace {

// The two-sided 95 % normal quantile.
constexpr double kZ95 = 1.959963984540054;

}  // namespace

LeaveOneOut leave_one_out_points(const GaussianProcess::State& state) {
  const Eigen::Index n = state.x_train.rows();
  Eigen::MatrixXd inverse = state.cholesky;
  if (n < 2 || !inverse_from_cholesky(inverse)) return {};
  if (state.mean_estimated) {  // needs whole rows of K⁻¹; simple kriging reads only its diagonal
    inverse.triangularView<Eigen::StrictlyUpper>() = inverse.transpose().eval();
    const Eigen::VectorXd k_inv_ones = inverse.rowwise().sum();
    inverse -= k_inv_ones * k_inv_ones.transpose() / k_inv_ones.sum();
  }
  LeaveOneOut loo;
  loo.error.resize(n);
  loo.std.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double k_inv_ii = inverse(i, i);
    loo.error(i) = state.y_scale * state.alpha(i) / k_inv_ii;
    loo.std(i) = state.y_scale / std::sqrt(k_inv_ii);
  }
  return loo;
}

void leave_one_out(const GaussianProcess::State& state, GpTrainingSummary& summary) {
  const LeaveOneOut loo = leave_one_out_points(state);
  const Eigen::Index n = loo.error.size();
  if (n == 0) return;
  double sum_rel = 0.0, max_rel = 0.0, sum_sq = 0.0, sum_standardised_sq = 0.0;
  Eigen::Index covered = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double error = loo.error(i), std = loo.std(i);
    const double rel = relative_error(error, state.y_train(i));
    sum_rel += rel;
    max_rel = std::max(max_rel, rel);
    sum_sq += error * error;
    sum_standardised_sq += (error / std) * (error / std);
    if (std::abs(error) <= kZ95 * std) ++covered;
  }
  summary.loo_mean_relative_error = sum_rel / static_cast<double>(n);
  summary.loo_max_relative_error = max_rel;
  summary.loo_rmse = std::sqrt(sum_sq / static_cast<double>(n));
  summary.loo_coverage_95 = static_cast<double>(covered) / static_cast<double>(n);
  summary.loo_standardised_rms = std::sqrt(sum_standardised_sq / static_cast<double>(n));
}


}  // namespace mufric
