#include "surrogate/gp_training.hpp"

#include <nlopt.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>

#include "common/error.hpp"
#include "common/version.hpp"
#include "surrogate/cholesky.hpp"

namespace mufric {
namespace {

// Returned to the optimiser where the covariance cannot be factorised: finite, so L-BFGS's line
// search backs off instead of propagating infinities.
constexpr double kFailedLml = -1e30;
// Outputs whose population std is below this fraction of |mean| are treated as constant.
constexpr double kConstantOutputRelative = 1e-12;
// Relative errors divide by max(|μ|, floor) so that μ = 0 does not divide by zero.
constexpr double kRelativeErrorFloor = 1e-12;
// A hyper-parameter closer than this (in log units) to a bound is reported as "at the bound".
constexpr double kAtBoundLog = 1e-2;
constexpr double kZ95 = 1.959963984540054;

// The best point is tracked here rather than trusted from NLopt's return: with jitter the LML is
// slightly discontinuous and L-BFGS may end in NLOPT_FAILURE after having found a good point.
struct StartContext {
  LogMarginalLikelihood* lml;
  int evaluations = 0;
  std::string last_failure;
  double best_lml = kFailedLml;
  Eigen::VectorXd best_theta;
};

double nlopt_objective(unsigned p, const double* x, double* grad, void* data) {
  auto* ctx = static_cast<StartContext*>(data);
  ++ctx->evaluations;
  const Eigen::VectorXd theta = Eigen::Map<const Eigen::VectorXd>(x, p);
  const auto value = (*ctx->lml)(theta, grad != nullptr);
  if (!value.ok) {
    ctx->last_failure = value.reason;
    if (grad) std::fill(grad, grad + p, 0.0);
    return kFailedLml;
  }
  if (grad) std::copy(value.gradient.data(), value.gradient.data() + p, grad);
  if (value.lml > ctx->best_lml) {
    ctx->best_lml = value.lml;
    ctx->best_theta = theta;
  }
  return value.lml;
}

std::string nlopt_outcome(nlopt_result r) {
  switch (r) {
    case NLOPT_SUCCESS: return "success";
    case NLOPT_STOPVAL_REACHED: return "stopval reached";
    case NLOPT_FTOL_REACHED: return "converged (ftol)";
    case NLOPT_XTOL_REACHED: return "converged (xtol)";
    case NLOPT_MAXEVAL_REACHED: return "evaluation limit reached";
    case NLOPT_MAXTIME_REACHED: return "time limit reached";
    case NLOPT_ROUNDOFF_LIMITED: return "converged (roundoff-limited)";
    case NLOPT_FAILURE: return "nlopt failure";
    case NLOPT_INVALID_ARGS: return "invalid arguments";
    case NLOPT_OUT_OF_MEMORY: return "out of memory";
    case NLOPT_FORCED_STOP: return "forced stop";
    default: return "nlopt result " + std::to_string(static_cast<int>(r));
  }
}

struct LogBounds {
  Eigen::VectorXd lo, hi;
};

LogBounds log_bounds(const GpBounds& b, Eigen::Index dims, bool noise_term) {
  const Eigen::Index p = dims + (noise_term ? 2 : 1);
  LogBounds lb{Eigen::VectorXd(p), Eigen::VectorXd(p)};
  lb.lo(0) = std::log(b.signal_variance_lo);
  lb.hi(0) = std::log(b.signal_variance_hi);
  lb.lo.segment(1, dims).setConstant(std::log(b.length_scale_lo));
  lb.hi.segment(1, dims).setConstant(std::log(b.length_scale_hi));
  if (noise_term) {
    lb.lo(p - 1) = std::log(b.noise_variance_lo);
    lb.hi(p - 1) = std::log(b.noise_variance_hi);
  }
  for (Eigen::Index i = 0; i < p; ++i) {
    if (!(lb.lo(i) < lb.hi(i))) throw Error("hyper-parameter bounds: lower bound is not below upper bound");
  }
  return lb;
}

GpStartReport run_start(const Eigen::MatrixXd& x_unit, const Eigen::VectorXd& y, const GpTrainingOptions& options,
                        const LogBounds& bounds, const Eigen::VectorXd& start) {
  const auto t0 = std::chrono::steady_clock::now();
  GpStartReport report;
  report.initial_log = start;
  LogMarginalLikelihood lml(x_unit, y, options.noise_term);
  StartContext ctx{&lml, 0, {}, kFailedLml, start};
  Eigen::VectorXd theta = start;
  double best = kFailedLml;
  if (options.optimise) {
    const auto p = static_cast<unsigned>(start.size());
    nlopt_opt opt = nlopt_create(NLOPT_LD_LBFGS, p);
    nlopt_set_lower_bounds(opt, bounds.lo.data());
    nlopt_set_upper_bounds(opt, bounds.hi.data());
    nlopt_set_max_objective(opt, nlopt_objective, &ctx);
    nlopt_set_ftol_rel(opt, options.relative_tolerance);
    nlopt_set_maxeval(opt, options.max_evaluations);
    const nlopt_result result = nlopt_optimize(opt, theta.data(), &best);
    nlopt_destroy(opt);
    report.outcome = nlopt_outcome(result);
    if (ctx.best_lml > best || !std::isfinite(best)) {
      best = ctx.best_lml;
      theta = ctx.best_theta;
    }
    report.ok = best > kFailedLml;
    if (report.ok && result < 0) report.outcome += " (best evaluated point kept)";
  } else {
    const auto value = lml(theta, false);
    ctx.evaluations = 1;
    best = value.ok ? value.lml : kFailedLml;
    report.ok = value.ok;
    report.outcome = value.ok ? "fixed hyper-parameters" : value.reason;
  }
  if (!report.ok && !ctx.last_failure.empty()) report.outcome += ": " + ctx.last_failure;
  report.final_log = theta;
  report.log_marginal_likelihood = best;
  report.evaluations = ctx.evaluations;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

}  // namespace

LogMarginalLikelihood::LogMarginalLikelihood(const Eigen::MatrixXd& x_unit, const Eigen::VectorXd& y, bool noise_term)
    : x_unit_(x_unit), y_(y), noise_term_(noise_term) {}

LogMarginalLikelihood::Value LogMarginalLikelihood::operator()(const Eigen::VectorXd& theta, bool with_gradient) {
  const Eigen::Index n = x_unit_.rows();
  const Eigen::Index d = x_unit_.cols();
  const auto hyper = GpHyperParameters::from_log(theta, d, noise_term_);
  Value value;
  rbf_signal_covariance(x_unit_, hyper, kf_);
  const auto chol = cholesky_with_jitter(kf_, hyper.noise_variance, factor_);
  value.jitter = chol.jitter;
  if (!chol.ok) {
    value.reason = chol.reason;
    return value;
  }
  Eigen::VectorXd alpha = factor_.triangularView<Eigen::Lower>().solve(y_);
  const double data_fit = alpha.squaredNorm();
  factor_.triangularView<Eigen::Lower>().transpose().solveInPlace(alpha);
  const double log_det_half = factor_.diagonal().array().log().sum();
  value.lml = -0.5 * data_fit - log_det_half - 0.5 * static_cast<double>(n) * std::log(2.0 * std::numbers::pi);
  if (!std::isfinite(value.lml)) {
    value.reason = "log marginal likelihood is not finite";
    return value;
  }
  value.ok = true;
  if (!with_gradient) return value;

  // ∂L/∂θ_j = ½ tr((ααᵀ − K⁻¹) ∂K/∂θ_j), summed over the lower triangle (R&W eq. 5.9).
  if (!inverse_from_cholesky(factor_)) {
    value.ok = false;
    value.reason = "dpotri failed on a successful Cholesky factor";
    return value;
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

void leave_one_out(const GaussianProcess::State& state, GpTrainingSummary& summary) {
  const Eigen::Index n = state.x_train.rows();
  Eigen::MatrixXd inverse = state.cholesky;
  if (n < 2 || !inverse_from_cholesky(inverse)) return;
  double sum_rel = 0.0, max_rel = 0.0, sum_sq = 0.0;
  Eigen::Index covered = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double k_inv_ii = inverse(i, i);
    const double error = state.y_scale * state.alpha(i) / k_inv_ii;
    const double std = state.y_scale / std::sqrt(k_inv_ii);
    const double rel = std::abs(error) / std::max(std::abs(state.y_train(i)), kRelativeErrorFloor);
    sum_rel += rel;
    max_rel = std::max(max_rel, rel);
    sum_sq += error * error;
    if (std::abs(error) <= kZ95 * std) ++covered;
  }
  summary.loo_mean_relative_error = sum_rel / static_cast<double>(n);
  summary.loo_max_relative_error = max_rel;
  summary.loo_rmse = std::sqrt(sum_sq / static_cast<double>(n));
  summary.loo_coverage_95 = static_cast<double>(covered) / static_cast<double>(n);
}

GaussianProcess train_gaussian_process(const TrainingSet& data, const GpTrainingOptions& options,
                                       GpTrainingReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  GpTrainingReport report;
  const Eigen::Index n = data.x.rows();
  const auto d = static_cast<Eigen::Index>(data.inputs.size());
  if (n == 0) throw Error("training set is empty");
  if (data.x.cols() != d) throw Error("training inputs have " + std::to_string(data.x.cols()) + " columns for " +
                                      std::to_string(d) + " declared inputs");
  if (!data.x.allFinite() || !data.mu.allFinite()) throw Error("training data contain non-finite values");
  for (const auto& input : data.inputs) {
    if (!(input.lo < input.hi)) {
      throw Error("input '" + input.name + "' has an empty box [" + std::to_string(input.lo) + ", " +
                  std::to_string(input.hi) + "]; it cannot be scaled (is it constant in the data?)");
    }
  }

  GaussianProcess::State state;
  state.inputs = data.inputs;
  state.x_train = data.x;
  state.y_train = data.mu;
  state.y_mean = data.mu.mean();
  const double y_std = std::sqrt((data.mu.array() - state.y_mean).square().mean());
  if (!(y_std > kConstantOutputRelative * std::abs(state.y_mean)) || y_std == 0.0) {
    state.y_scale = 1.0;
    report.warnings.push_back("outputs are constant (μ = " + std::to_string(state.y_mean) +
                              "): the model predicts that value with a near-zero interval");
  } else {
    state.y_scale = y_std;
  }
  const Eigen::MatrixXd x_unit = to_unit_box(data.x, data.inputs);
  const Eigen::VectorXd y = (data.mu.array() - state.y_mean) / state.y_scale;

  const LogBounds bounds = log_bounds(options.bounds, d, options.noise_term);
  GpHyperParameters initial = options.initial;
  if (initial.length_scales.size() == 0) {
    initial.signal_variance = 1.0;
    initial.length_scales = Eigen::VectorXd::Constant(d, 0.5);
    initial.noise_variance = 1e-5;
  }
  if (initial.length_scales.size() != d) throw Error("initial length_scales: wrong number of inputs");
  initial.noise_term = options.noise_term;
  std::vector<Eigen::VectorXd> starts{initial.to_log().cwiseMax(bounds.lo).cwiseMin(bounds.hi)};
  if (options.optimise) {
    std::mt19937_64 rng(options.seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int r = 0; r < options.restarts; ++r) {
      Eigen::VectorXd theta(bounds.lo.size());
      for (Eigen::Index i = 0; i < theta.size(); ++i) theta(i) = bounds.lo(i) + unit(rng) * (bounds.hi(i) - bounds.lo(i));
      starts.push_back(theta);
    }
  }

  report.starts.resize(starts.size());
  const int threads = std::min<int>(options.threads > 0 ? options.threads : omp_get_num_procs(),
                                    static_cast<int>(starts.size()));
  if (threads > 1) {
    // Starts in parallel, each with single-threaded BLAS: independent work scales better than a
    // shared multi-threaded factorisation of a few-hundred-row matrix.
    SingleThreadedBlas guard;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (size_t s = 0; s < starts.size(); ++s) report.starts[s] = run_start(x_unit, y, options, bounds, starts[s]);
  } else {
    for (size_t s = 0; s < starts.size(); ++s) report.starts[s] = run_start(x_unit, y, options, bounds, starts[s]);
  }

  for (size_t s = 0; s < report.starts.size(); ++s) {
    const auto& start = report.starts[s];
    if (start.ok && (report.best_start < 0 ||
                     start.log_marginal_likelihood > report.starts[static_cast<size_t>(report.best_start)].log_marginal_likelihood)) {
      report.best_start = static_cast<int>(s);
    }
  }
  if (report.best_start < 0) {
    std::string reasons;
    for (const auto& start : report.starts) reasons += "\n  start: " + start.outcome;
    throw Error("Gaussian process fit failed: no start produced a factorisable covariance" + reasons);
  }
  const auto& best = report.starts[static_cast<size_t>(report.best_start)];
  state.hyper = GpHyperParameters::from_log(best.final_log, d, options.noise_term);

  Eigen::MatrixXd kf;
  rbf_signal_covariance(x_unit, state.hyper, kf);
  const auto chol = cholesky_with_jitter(kf, state.hyper.noise_variance, state.cholesky);
  if (!chol.ok) throw Error("Gaussian process fit failed at the optimum: " + chol.reason);
  state.jitter = chol.jitter;
  report.jitter = chol.jitter;
  state.alpha = state.cholesky.triangularView<Eigen::Lower>().solve(y);
  state.cholesky.triangularView<Eigen::Lower>().transpose().solveInPlace(state.alpha);

  auto& summary = state.summary;
  summary.log_marginal_likelihood = best.log_marginal_likelihood;
  summary.starts = static_cast<long long>(report.starts.size());
  summary.best_start = report.best_start;
  summary.dataset_path = data.source_path;
  summary.dataset_sha256 = data.source_hash;
  summary.code_version = code_version();
  summary.created_utc = utc_timestamp();
  leave_one_out(state, summary);

  if (chol.jitter > 0.0) {
    std::ostringstream w;
    w << "jitter " << chol.jitter << " added to the covariance diagonal (" << chol.attempts
      << " factorisation attempts): inputs are nearly duplicated";
    report.warnings.push_back(w.str());
  }
  const Eigen::VectorXd theta = best.final_log;
  auto at_bound = [&](Eigen::Index i, const std::string& name) {
    if (theta(i) - bounds.lo(i) < kAtBoundLog) report.warnings.push_back(name + " is at its lower bound");
    if (bounds.hi(i) - theta(i) < kAtBoundLog) report.warnings.push_back(name + " is at its upper bound");
  };
  if (options.optimise) {
    at_bound(0, "signal variance");
    for (Eigen::Index k = 0; k < d; ++k) at_bound(1 + k, "length scale of " + data.inputs[static_cast<size_t>(k)].name);
    if (options.noise_term) at_bound(d + 1, "noise variance");
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary.seconds = report.seconds;
  if (report_out) *report_out = report;
  return GaussianProcess(std::move(state));
}

}  // namespace mufric
