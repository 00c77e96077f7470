#include "surrogate/gp/gp_training.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/error.hpp"
#include "surrogate/core/cholesky.hpp"

// The log marginal likelihood of the GP's hyper-parameters with its analytic gradient (R&W eq. 5.8-5.9),
// what the training maximises.
namespace mufric {

LogMarginalLikelihood::LogMarginalLikelihood(const Eigen::MatrixXd& x_unit, const Eigen::VectorXd& y, bool noise_term,
                                             Eigen::VectorXd known_noise, bool restricted)
    : x_unit_(x_unit), y_(y), noise_term_(noise_term), known_noise_(std::move(known_noise)), restricted_(restricted) {}

LogMarginalLikelihood::Value LogMarginalLikelihood::operator()(const Eigen::VectorXd& theta, bool with_gradient) {
  const Eigen::Index n = x_unit_.rows();
  const Eigen::Index d = x_unit_.cols();
  const auto hyper = GpHyperParameters::from_log(theta, d, noise_term_);
  Value value;
  rbf_signal_covariance(x_unit_, hyper, kf_);
  const auto chol = cholesky_with_jitter(kf_, hyper.noise_variance, factor_, known_noise_);
  value.jitter = chol.jitter;
  if (!chol.ok) {
    value.reason = chol.reason;
    return value;
  }
  Eigen::VectorXd alpha = factor_.triangularView<Eigen::Lower>().solve(y_);
  double data_fit = alpha.squaredNorm();
  factor_.triangularView<Eigen::Lower>().transpose().solveInPlace(alpha);
  const double log_det_half = factor_.diagonal().array().log().sum();
  double contrasts = static_cast<double>(n);
  // REML: yᵀPy with P = K⁻¹ − ggᵀ/c, g = K⁻¹1, c = 1ᵀg; −½ log c; n − 1 contrasts; α becomes Py.
  Eigen::VectorXd g;
  double precision = 0.0;
  if (restricted_) {
    g = factor_.triangularView<Eigen::Lower>().solve(Eigen::VectorXd::Ones(n));
    precision = g.squaredNorm();
    factor_.triangularView<Eigen::Lower>().transpose().solveInPlace(g);
    const double beta = alpha.sum() / precision;
    data_fit -= beta * beta * precision;
    alpha -= beta * g;
    contrasts -= 1.0;
  }
  value.lml = -0.5 * data_fit - log_det_half - 0.5 * contrasts * std::log(2.0 * std::numbers::pi);
  if (restricted_) value.lml -= 0.5 * std::log(precision);
  if (!std::isfinite(value.lml)) {
    value.reason = "log marginal likelihood is not finite";
    return value;
  }
  value.ok = true;
  if (!with_gradient) return value;

  // ∂L/∂θ_j = ½ tr((ααᵀ − K⁻¹) ∂K/∂θ_j), summed over the lower triangle (R&W eq. 5.9); REML: K⁻¹ → P.
  if (!inverse_from_cholesky(factor_)) {
    value.ok = false;
    value.reason = "dpotri failed on a successful Cholesky factor";
    return value;
  }
  if (restricted_) {
    for (Eigen::Index j = 0; j < n; ++j) factor_.col(j).tail(n - j) -= g.tail(n - j) * (g(j) / precision);
  }
  scaled_ = x_unit_ * hyper.length_scales.cwiseInverse().asDiagonal();
  double signal_sum = 0.0;
  double trace_w = 0.0;
  Eigen::VectorXd length_sums = Eigen::VectorXd::Zero(d);
  Eigen::ArrayXd w(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double w_jj = alpha(j) * alpha(j) - factor_(j, j);
    trace_w += w_jj;
    signal_sum += w_jj * kf_(j, j);
    const Eigen::Index len = n - j - 1;
    if (len == 0) continue;
    w.head(len) = (alpha.tail(len).array() * alpha(j) - factor_.col(j).tail(len).array()) * kf_.col(j).tail(len).array();
    signal_sum += 2.0 * w.head(len).sum();
    for (Eigen::Index k = 0; k < d; ++k) {
      length_sums(k) += 2.0 * (w.head(len) * (scaled_.col(k).tail(len).array() - scaled_(j, k)).square()).sum();
    }
  }
  value.gradient.resize(theta.size());
  value.gradient(0) = 0.5 * signal_sum;
  value.gradient.segment(1, d) = 0.5 * length_sums;
  if (noise_term_) value.gradient(d + 1) = 0.5 * hyper.noise_variance * trace_w;
  return value;
}


}  // namespace mufric
