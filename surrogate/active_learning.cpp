#include "surrogate/active_learning.hpp"

#include <cmath>

#include "common/error.hpp"

namespace mufric {
namespace {

// σ² exp(−½ Σ ((aᵢ − bᵢ)/lᵢ)²) between the rows of a and b (unit-box coordinates).
Eigen::MatrixXd rbf(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const GpHyperParameters& h) {
  const Eigen::RowVectorXd inverse_length = h.length_scales.cwiseInverse().transpose();
  const Eigen::MatrixXd as = a.array().rowwise() * inverse_length.array();
  const Eigen::MatrixXd bs = b.array().rowwise() * inverse_length.array();
  const Eigen::VectorXd a2 = as.rowwise().squaredNorm(), b2 = bs.rowwise().squaredNorm();
  Eigen::MatrixXd d2 = -2.0 * as * bs.transpose();
  d2.colwise() += a2;
  d2.rowwise() += b2.transpose();
  Eigen::Map<Eigen::ArrayXd> correlation(d2.data(), d2.size());
  correlation = correlation.max(0.0);  // round-off in the expanded square
  rbf_correlation_in_place(correlation);  // the model's own kernel values (same floor)
  return h.signal_variance * d2;
}

}  // namespace

std::vector<VariancePick> pick_by_posterior_variance(const GaussianProcess& gp, const Eigen::MatrixXd& given,
                                                     int batch, const Eigen::MatrixXd& tried) {
  const auto& s = gp.state();
  if (given.cols() != static_cast<Eigen::Index>(s.inputs.size()) || (tried.size() > 0 && tried.cols() != given.cols())) {
    throw Error("active learning: candidates have " + std::to_string(given.cols()) + " columns, the model " +
                std::to_string(s.inputs.size()) + " inputs");
  }
  // The tried points ride along after the candidates: conditioned on, never picked.
  Eigen::MatrixXd candidates(given.rows() + tried.rows(), given.cols());
  candidates.topRows(given.rows()) = given;
  if (tried.rows() > 0) candidates.bottomRows(tried.rows()) = tried;
  const Eigen::MatrixXd xc = to_unit_box(candidates, s.inputs), xt = to_unit_box(s.x_train, s.inputs);
  // Posterior covariance among the candidates: K_cc − K_cx K⁻¹ K_xc with K = L Lᵀ.
  const Eigen::MatrixXd v = s.cholesky.triangularView<Eigen::Lower>().solve(rbf(xt, xc, s.hyper));
  Eigen::MatrixXd sigma = rbf(xc, xc, s.hyper);
  sigma.noalias() -= v.transpose() * v;
  const double noise = s.hyper.noise_variance + s.jitter;
  const auto condition_on = [&](Eigen::Index k) {
    const Eigen::VectorXd column = sigma.col(k);
    sigma.noalias() -= column * column.transpose() / (column(k) + std::max(noise, 1e-12));
  };
  for (Eigen::Index t = given.rows(); t < candidates.rows(); ++t) condition_on(t);
  std::vector<VariancePick> picks;
  std::vector<bool> taken(static_cast<size_t>(given.rows()), false);
  for (int b = 0; b < batch && static_cast<Eigen::Index>(picks.size()) < given.rows(); ++b) {
    Eigen::Index best = -1;
    for (Eigen::Index i = 0; i < given.rows(); ++i) {
      if (!taken[static_cast<size_t>(i)] && (best < 0 || sigma(i, i) > sigma(best, best))) best = i;
    }
    taken[static_cast<size_t>(best)] = true;
    picks.push_back({best, s.y_scale * std::sqrt(std::max(sigma(best, best), 0.0))});
    condition_on(best);
  }
  return picks;
}

}  // namespace mufric
