#include "surrogate/calibration/held_out_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "common/wording.hpp"

namespace mufric {
namespace {

// Zhang & Stephens (2009, Technometrics 51:316) empirical-Bayes fit of a generalised Pareto
// distribution to sorted exceedances, with Vehtari et al.'s weak prior on k (2024, app. C; the form
// of the loo package's gpdfit): returns (k, σ).
std::pair<double, double> fit_generalised_pareto(const std::vector<double>& sorted) {
  constexpr double kPriorB = 3.0, kPriorK = 10.0;
  const double n = static_cast<double>(sorted.size());
  const int m = 30 + static_cast<int>(std::sqrt(n));
  const double quartile = sorted[static_cast<size_t>(std::floor(n / 4.0 + 0.5)) - 1];
  std::vector<double> b(static_cast<size_t>(m)), k(static_cast<size_t>(m)), length(static_cast<size_t>(m));
  for (int j = 0; j < m; ++j) {
    b[j] = 1.0 - std::sqrt(m / (j + 1.0 - 0.5));
    b[j] = b[j] / (kPriorB * quartile) + 1.0 / sorted.back();
    double sum = 0.0;
    for (double x : sorted) sum += std::log1p(-b[j] * x);
    k[j] = sum / n;
    length[j] = n * (std::log(-b[j] / k[j]) - k[j] - 1.0);
  }
  std::vector<double> weight(static_cast<size_t>(m));
  for (int j = 0; j < m; ++j) {
    double sum = 0.0;
    for (int l = 0; l < m; ++l) sum += std::exp(length[l] - length[j]);
    weight[j] = 1.0 / sum;
  }
  double total = 0.0, b_mean = 0.0;
  for (int j = 0; j < m; ++j) {
    if (!(weight[j] >= 10.0 * std::numeric_limits<double>::epsilon())) continue;  // negligible
    total += weight[j];
    b_mean += weight[j] * b[j];
  }
  b_mean /= total;
  double sum = 0.0;
  for (double x : sorted) sum += std::log1p(-b_mean * x);
  const double k_hat = sum / n;
  const double sigma = -k_hat / b_mean;
  return {(n * k_hat + kPriorK * 0.5) / (n + kPriorK), sigma};
}

// The generalised Pareto's quantile at probability p.
double pareto_quantile(double p, double k, double sigma) {
  if (std::abs(k) < 1e-12) return -sigma * std::log1p(-p);
  return sigma * std::expm1(-k * std::log1p(-p)) / k;
}

double log_sum_exp(const Eigen::VectorXd& x) {
  const double top = x.maxCoeff();
  return top + std::log((x.array() - top).exp().sum());
}

}  // namespace

SmoothedWeights pareto_smoothed_weights(const Eigen::VectorXd& log_ratios) {
  const Eigen::Index s = log_ratios.size();
  Eigen::VectorXd x = log_ratios.array() - log_ratios.maxCoeff();
  // The tail: the M largest ratios, M = min(0.2 S, 3 √S) (Vehtari et al. 2024, sec. 3).
  const auto tail_length = static_cast<Eigen::Index>(std::ceil(std::min(0.2 * static_cast<double>(s), 3.0 * std::sqrt(static_cast<double>(s)))));
  std::vector<Eigen::Index> order(static_cast<size_t>(s));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return x(a) < x(b); });
  SmoothedWeights out;
  if (tail_length < 5 || tail_length >= s) {
    out.pareto_k = std::numeric_limits<double>::infinity();
  } else {
    const double cutoff = std::max(x(order[static_cast<size_t>(s - tail_length - 1)]), std::log(std::numeric_limits<double>::min()));
    const double exp_cutoff = std::exp(cutoff);
    std::vector<Eigen::Index> tail;
    for (Eigen::Index i : order)
      if (x(i) > cutoff) tail.push_back(i);
    if (tail.size() < 5) {
      out.pareto_k = std::numeric_limits<double>::infinity();
    } else {
      std::vector<double> exceedances;
      for (Eigen::Index i : tail) exceedances.push_back(std::exp(x(i)) - exp_cutoff);
      const auto [k, sigma] = fit_generalised_pareto(exceedances);
      out.pareto_k = k;
      if (std::isfinite(k)) {
        const double count = static_cast<double>(tail.size());
        for (size_t r = 0; r < tail.size(); ++r)
          x(tail[r]) = std::min(0.0, std::log(pareto_quantile((static_cast<double>(r) + 0.5) / count, k, sigma) + exp_cutoff));
      }
    }
  }
  out.log_weights = x.array() - log_sum_exp(x);
  return out;
}

ConditionalPredictives conditional_predictives(const CalibrationProblem& problem, const Eigen::VectorXd& natural) {
  const CalibrationProblem::Likelihood likelihood = problem.likelihood_at(problem.point_at(natural));
  const Eigen::Index n = likelihood.residual.size();
  const Eigen::VectorXd alpha = likelihood.factor.solve(likelihood.residual);
  // diag(Σ⁻¹): the squared column norms of L⁻¹.
  const Eigen::MatrixXd inverse_factor =
      likelihood.factor.matrixL().solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::VectorXd precision_diagonal = inverse_factor.colwise().squaredNorm().transpose();
  ConditionalPredictives out;
  out.variance = precision_diagonal.cwiseInverse();
  // y_i − mean_i = α_i / Q_ii: the conditional residual.
  const Eigen::VectorXd residual = alpha.cwiseQuotient(precision_diagonal);
  out.mean = problem.data().mu - residual;
  out.log_density = -0.5 * std::log(2.0 * std::numbers::pi) + 0.5 * precision_diagonal.array().log() -
                    0.5 * alpha.array().square() / precision_diagonal.array();
  return out;
}

HeldOutCheck leave_one_out(const CalibrationProblem& problem, const CalibrationResult& result, int max_samples) {
  HeldOutCheck check;
  const Eigen::Index total = result.samples.rows(), n = problem.data().rows();
  if (total < 2 || n == 0) return check;
  const Eigen::Index s = std::min<Eigen::Index>(total, max_samples);
  Eigen::MatrixXd log_density(s, n), mean(s, n), variance(s, n);
  for (Eigen::Index k = 0; k < s; ++k) {
    const Eigen::Index row = k * total / s;
    const ConditionalPredictives p = conditional_predictives(problem, result.samples.row(row).transpose());
    log_density.row(k) = p.log_density.transpose();
    mean.row(k) = p.mean.transpose();
    variance.row(k) = p.variance.transpose();
  }
  check.samples = static_cast<int>(s);
  double lppd = 0.0, absolute_error = 0.0;
  int covered = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    // p(coordinates | y_−i) ∝ p(coordinates | y) / p(y_i | y_−i, coordinates).
    const SmoothedWeights w = pareto_smoothed_weights(-log_density.col(i));
    RowHeldOut r;
    r.pareto_k = w.pareto_k;
    r.elpd = log_sum_exp(w.log_weights + log_density.col(i));
    const Eigen::ArrayXd weights = w.log_weights.array().exp();
    r.predicted_mean = (weights * mean.col(i).array()).sum();
    r.predicted_sd = std::sqrt(std::max(0.0, (weights * (variance.col(i).array() + mean.col(i).array().square())).sum() -
                                                  r.predicted_mean * r.predicted_mean));
    lppd += log_sum_exp(log_density.col(i)) - std::log(static_cast<double>(s));
    const double error = problem.data().mu(i) - r.predicted_mean;
    absolute_error += std::abs(error);
    if (std::abs(error) <= 1.959963984540054 * r.predicted_sd) ++covered;
    if (!(r.pareto_k <= kParetoKUnreliable)) ++check.unreliable;
    check.rows.push_back(r);
  }
  Eigen::VectorXd elpd(n);
  for (Eigen::Index i = 0; i < n; ++i) elpd(i) = check.rows[static_cast<size_t>(i)].elpd;
  check.elpd = elpd.sum();
  const double mean_elpd = elpd.mean();
  check.elpd_se = n > 1 ? std::sqrt(static_cast<double>(n) * (elpd.array() - mean_elpd).square().sum() / static_cast<double>(n - 1)) : 0.0;
  check.p_loo = lppd - check.elpd;
  check.mean_abs_error = absolute_error / static_cast<double>(n);
  check.covered = static_cast<double>(covered) / static_cast<double>(n);
  return check;
}

std::string describe_held_out(const CalibrationProblem& problem, const HeldOutCheck& check) {
  if (check.rows.empty()) return {};
  const auto n = static_cast<long long>(check.rows.size());
  std::string text = text_printf(
      "each measurement predicted from the others (PSIS-LOO over %d posterior points, no rerun): elpd %.2f (SE %.2f), "
      "p_loo %.1f; mean |error| %.3g, %s of %lld inside its 95 %% interval\n",
      check.samples, check.elpd, check.elpd_se, check.p_loo, check.mean_abs_error,
      std::to_string(static_cast<long long>(std::lround(check.covered * static_cast<double>(n)))).c_str(), n);
  text += "  (elpd: the held-out log predictive density, higher is better; compare law variants (--fix, --discrepancy) on the "
          "same rows by it, a difference of a few SEs or more; p_loo: the effective number of fitted parameters)\n";
  if (check.unreliable > 0) {
    std::string rows;
    for (size_t i = 0; i < check.rows.size(); ++i)
      if (!(check.rows[i].pareto_k <= kParetoKUnreliable))
        rows += (rows.empty() ? std::string() : std::string(", ")) + problem.data().row_names[i] +
                text_printf(" (k %.2f)", check.rows[i].pareto_k);
    text += "warning: the held-out estimate is unreliable for " + count_of(check.unreliable, "row", "rows") + " (Pareto k over " +
            text_printf("%.1f", kParetoKUnreliable) + ": the row pulls the posterior much): " + rows +
            "; hold it out and calibrate again for its figure\n";
  }
  return text;
}

}  // namespace mufric
