#include "surrogate/gp/active_learning.hpp"

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

std::vector<ImsePick> pick_by_imse_reduction(const GaussianProcess& gp, const Eigen::MatrixXd& given,
                                             const Eigen::VectorXd& candidate_noise, const Eigen::MatrixXd& reference,
                                             int batch, const Eigen::MatrixXd& tried) {
  const auto& s = gp.state();
  const auto d = static_cast<Eigen::Index>(s.inputs.size());
  if (given.cols() != d || reference.cols() != d || (tried.size() > 0 && tried.cols() != d)) {
    throw Error("active learning: candidates, reference or tried points have the wrong number of inputs (the model has " +
                std::to_string(d) + ")");
  }
  if (candidate_noise.size() != given.rows() || !(candidate_noise.array() >= 0.0).all()) {
    throw Error("active learning: one noise variance >= 0 per candidate");
  }
  if (reference.rows() == 0) throw Error("active learning: no reference points");
  // Columns: the reference points, the candidates, the tried points. Σ(ref, cand) is kept whole and
  // updated by the rank-one term of each point conditioned on; a conditioned point's whole column is
  // formed on demand from V = L⁻¹ K(X, ·) and the earlier updates.
  const Eigen::Index m_ref = reference.rows(), m_cand = given.rows();
  Eigen::MatrixXd points(m_ref + m_cand + tried.rows(), d);
  points << reference, given, tried;
  const Eigen::MatrixXd xp = to_unit_box(points, s.inputs), xt = to_unit_box(s.x_train, s.inputs);
  const Eigen::MatrixXd v = s.cholesky.triangularView<Eigen::Lower>().solve(rbf(xt, xp, s.hyper));
  Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(points.rows(), s.hyper.signal_variance) - v.colwise().squaredNorm().transpose();
  Eigen::MatrixXd cross = rbf(xp.topRows(m_ref), xp.middleRows(m_ref, m_cand), s.hyper);
  cross.noalias() -= v.leftCols(m_ref).transpose() * v.middleCols(m_ref, m_cand);
  std::vector<Eigen::VectorXd> updates;  // Σ(·, k) / √(Σ(k, k) + τ²_k) of each point conditioned on
  const auto condition_on = [&](Eigen::Index j, double noise) {
    Eigen::VectorXd c = rbf(xp, xp.row(j), s.hyper) - v.transpose() * v.col(j);
    for (const auto& u : updates) c -= u * u(j);
    updates.push_back(c / std::sqrt(std::max(c(j) + noise, 1e-300)));
    const Eigen::VectorXd& u = updates.back();
    diagonal -= u.cwiseAbs2();
    cross.noalias() -= u.head(m_ref) * u.segment(m_ref, m_cand).transpose();
  };
  const double scale2 = s.y_scale * s.y_scale;
  const double tried_noise = s.hyper.noise_variance + s.jitter;
  for (Eigen::Index t = 0; t < tried.rows(); ++t) condition_on(m_ref + m_cand + t, std::max(tried_noise, 1e-12));
  std::vector<ImsePick> picks;
  std::vector<bool> taken(static_cast<size_t>(m_cand), false);
  for (int b = 0; b < batch && static_cast<Eigen::Index>(picks.size()) < m_cand; ++b) {
    const Eigen::RowVectorXd removed = cross.colwise().squaredNorm();
    Eigen::Index best = -1;
    double best_gain = -1.0;
    for (Eigen::Index i = 0; i < m_cand; ++i) {
      if (taken[static_cast<size_t>(i)]) continue;
      const double gain = removed(i) / (std::max(diagonal(m_ref + i), 0.0) + candidate_noise(i) / scale2) /
                          static_cast<double>(m_ref);
      if (gain > best_gain) {
        best_gain = gain;
        best = i;
      }
    }
    if (best < 0) break;
    taken[static_cast<size_t>(best)] = true;
    picks.push_back({best, best_gain * scale2, s.y_scale * std::sqrt(std::max(diagonal(m_ref + best), 0.0))});
    condition_on(m_ref + best, candidate_noise(best) / scale2);
  }
  return picks;
}

}  // namespace mufric
