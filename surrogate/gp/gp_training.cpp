#include "surrogate/gp/gp_training.hpp"

#include <nlopt.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <mutex>
#include <numbers>
#include <numeric>
#include <random>
#include <sstream>

#include "common/environment.hpp"
#include "common/error.hpp"
#include "common/version.hpp"
#include "common/wording.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/core/cholesky.hpp"
#include "surrogate/gp/gp_training_data.hpp"

namespace mufric {
namespace {

// Returned to the optimiser where the covariance cannot be factorised: finite, so L-BFGS's line
// search backs off instead of propagating infinities.
constexpr double kFailedLml = -1e30;
// A hyper-parameter closer than this (in log units) to a bound is reported as "at the bound".
constexpr double kAtBoundLog = 1e-2;
// Above this many points a full-data likelihood evaluation takes seconds: the fit says so up front.
constexpr Eigen::Index kSlowFitPoints = 3000;

// The best point is tracked here rather than trusted from NLopt's return: with jitter the LML is
// slightly discontinuous and L-BFGS may end in NLOPT_FAILURE after having found a good point.
// Progress lines from starts running in parallel: one at a time, each start at most every
// options.progress_seconds.
class TrainingProgress {
 public:
  explicit TrainingProgress(const std::function<void(const std::string&)>& sink) : sink_(sink) {}
  void say(const std::string& line) {
    if (!sink_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    sink_(line);
  }
  bool enabled() const { return static_cast<bool>(sink_); }

 private:
  const std::function<void(const std::string&)>& sink_;
  std::mutex mutex_;
};

struct StartContext {
  LogMarginalLikelihood* lml = nullptr;
  int evaluations = 0;
  std::string last_failure;
  double best_lml = kFailedLml;
  Eigen::VectorXd best_theta;
  // Set for a full-data climb that reports its progress.
  TrainingProgress* progress = nullptr;
  double progress_seconds = 0.0;
  std::string label;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now(), last_report = started;
};

void report_progress(StartContext& ctx) {
  if (ctx.progress == nullptr) return;
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - ctx.last_report).count() < ctx.progress_seconds) return;
  ctx.last_report = now;
  const double elapsed = std::chrono::duration<double>(now - ctx.started).count();
  std::ostringstream line;
  line << ctx.label << ": " << ctx.evaluations << " LML evaluations in " << std::fixed << std::setprecision(1) << elapsed
       << " s (" << elapsed / ctx.evaluations << " s each), best LML " << std::setprecision(3) << ctx.best_lml;
  ctx.progress->say(line.str());
}

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
  report_progress(*ctx);
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

struct LocalOptimum {
  Eigen::VectorXd theta;
  double lml = kFailedLml;
  int evaluations = 0;
  std::string outcome;
};

// One bounded L-BFGS run (NLopt's NLOPT_LD_LBFGS, Liu & Nocedal 1989) from `start`.
LocalOptimum maximise(LogMarginalLikelihood& lml, const Eigen::VectorXd& start, const GpTrainingOptions& options,
                      const LogBounds& bounds, TrainingProgress* progress = nullptr, std::string label = {}) {
  StartContext ctx;
  ctx.lml = &lml;
  ctx.best_theta = start;
  ctx.progress = progress;
  ctx.progress_seconds = options.progress_seconds;
  ctx.label = std::move(label);
  LocalOptimum result;
  result.theta = start;
  const auto p = static_cast<unsigned>(start.size());
  nlopt_opt opt = nlopt_create(NLOPT_LD_LBFGS, p);
  nlopt_set_lower_bounds(opt, bounds.lo.data());
  nlopt_set_upper_bounds(opt, bounds.hi.data());
  nlopt_set_max_objective(opt, nlopt_objective, &ctx);
  nlopt_set_ftol_rel(opt, options.relative_tolerance);
  nlopt_set_ftol_abs(opt, options.absolute_tolerance);
  nlopt_set_maxeval(opt, options.max_evaluations);
  const nlopt_result status = nlopt_optimize(opt, result.theta.data(), &result.lml);
  nlopt_destroy(opt);
  result.outcome = nlopt_outcome(status);
  if (ctx.best_lml > result.lml || !std::isfinite(result.lml)) {
    result.lml = ctx.best_lml;
    result.theta = ctx.best_theta;
  }
  if (result.lml > kFailedLml && status < 0) result.outcome += " (best evaluated point kept)";
  if (result.lml <= kFailedLml && !ctx.last_failure.empty()) result.outcome += ": " + ctx.last_failure;
  result.evaluations = ctx.evaluations;
  return result;
}

// Subset-stage optima closer than this in every log hyper-parameter are the same basin (1 %).
constexpr double kSameBasinLog = 1e-2;
// A subset optimum whose LML is this many nats below the best one is not refined on all data: on a
// few hundred points, 20 nats is a likelihood ratio of e²⁰ ≈ 5e8, and the gap grows with n.
constexpr double kHopelessSubsetGap = 20.0;

template <typename Work>
void for_each_parallel(size_t count, int threads, Work work) {
  if (threads > 1 && count > 1) {
    // Independent runs in parallel, each with single-threaded BLAS: this scales better than one
    // shared multi-threaded factorisation of a few-hundred-row matrix.
    SingleThreadedBlas guard;
#pragma omp parallel for num_threads(std::min<int>(threads, static_cast<int>(count))) schedule(dynamic, 1)
    for (size_t i = 0; i < count; ++i) work(i);
  } else {
    for (size_t i = 0; i < count; ++i) work(i);
  }
}


// Ordinary kriging's constant (Ankenman, Nelson & Staum 2010, eq. 7): β̂ = 1ᵀK⁻¹y / 1ᵀK⁻¹1 in
// normalised units, folded into y_mean, and α = K⁻¹(y − β̂1); α = K⁻¹y on entry.
void estimate_constant_mean(GaussianProcess::State& state) {
  const Eigen::Index n = state.alpha.size();
  Eigen::VectorXd k_inv_ones = state.cholesky.triangularView<Eigen::Lower>().solve(Eigen::VectorXd::Ones(n));
  state.cholesky.triangularView<Eigen::Lower>().transpose().solveInPlace(k_inv_ones);
  const double beta = state.alpha.sum() / k_inv_ones.sum();
  state.alpha -= beta * k_inv_ones;
  state.y_mean += state.y_scale * beta;
  state.mean_estimated = true;
}


// The first start (options.initial, or σ² = 1, l = 0.5 box widths, σn² = 1e-5) and, when optimising,
// options.restarts more drawn log-uniformly in the bounds from options.seed; all inside the bounds.
std::vector<Eigen::VectorXd> starting_points(const GpTrainingOptions& options, const LogBounds& bounds, Eigen::Index d) {
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
  return starts;
}

// Stage 1, a subset of the data (Chalupka, Williams & Murray 2013): each start first climbs the
// likelihood of a fixed random subset, ~(n/m)³ times cheaper per evaluation, when the data are large.
struct SubsetStage {
  bool used = false;
  std::vector<Eigen::VectorXd> optima;  // where each start's full-data stage begins (its start if unused or failed)
  std::vector<double> lml;              // each start's subset optimum (kFailedLml: none)
};

SubsetStage climb_on_a_subset(const NormalisedData& data, const Eigen::VectorXd& known_noise,
                              const GpTrainingOptions& options, const LogBounds& bounds,
                              const std::vector<Eigen::VectorXd>& starts, int threads, TrainingProgress& progress,
                              GpTrainingReport& report) {
  const Eigen::Index n = data.x_unit.rows(), d = data.x_unit.cols();
  SubsetStage stage{.used = options.optimise && options.subset_size > 0 && n > 2 * static_cast<Eigen::Index>(options.subset_size),
                    .optima = starts,
                    .lml = std::vector<double>(starts.size(), kFailedLml)};
  if (!stage.used) return stage;
  progress.say(count_of(static_cast<long long>(starts.size()), "start", "starts") + " on a subset of " +
               std::to_string(options.subset_size) + " of the " + std::to_string(n) + " points");
  std::vector<Eigen::Index> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::shuffle(order.begin(), order.end(), std::mt19937_64(options.seed ^ 0x5eed5eedULL));
  Eigen::MatrixXd x_subset(options.subset_size, d);
  Eigen::VectorXd y_subset(options.subset_size);
  Eigen::VectorXd noise_subset(known_noise.size() != 0 ? options.subset_size : 0);
  for (Eigen::Index k = 0; k < options.subset_size; ++k) {
    x_subset.row(k) = data.x_unit.row(order[static_cast<size_t>(k)]);
    y_subset(k) = data.y(order[static_cast<size_t>(k)]);
    if (noise_subset.size() != 0) noise_subset(k) = known_noise(order[static_cast<size_t>(k)]);
  }
  for_each_parallel(starts.size(), threads, [&](size_t s) {
    const auto t_start = std::chrono::steady_clock::now();
    LogMarginalLikelihood coarse(x_subset, y_subset, options.noise_term, noise_subset, options.estimate_mean);
    const LocalOptimum optimum = maximise(coarse, starts[s], options, bounds);
    report.starts[s].subset_evaluations = optimum.evaluations;
    stage.lml[s] = optimum.lml;
    if (optimum.lml > kFailedLml) stage.optima[s] = optimum.theta;
    report.starts[s].seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  });
  return stage;
}

// Stage 2's grouping, as in multi-level single linkage (Rinnooy Kan & Timmer 1987): starts whose
// subset optima coincide share one full-data run (a basin is climbed once). leader[s] is the start
// whose run s shares (s itself for a leader).
std::vector<size_t> basin_leaders(const SubsetStage& stage) {
  std::vector<size_t> leader(stage.optima.size());
  std::vector<size_t> leaders;
  for (size_t s = 0; s < stage.optima.size(); ++s) {
    leader[s] = s;
    if (stage.used) {
      for (const size_t l : leaders) {
        if ((stage.optima[s] - stage.optima[l]).cwiseAbs().maxCoeff() < kSameBasinLog) {
          leader[s] = l;
          break;
        }
      }
    }
    if (leader[s] == s) leaders.push_back(s);
  }
  return leader;
}

// Stage 2, all data: each basin's leader climbs from its subset optimum; a subset optimum far worse
// than the best is evaluated on all data but not refined; the other starts share their leader's result.
void climb_on_all_data(const NormalisedData& data, const Eigen::VectorXd& known_noise, const GpTrainingOptions& options,
                       const LogBounds& bounds, const SubsetStage& stage, int threads, TrainingProgress& progress,
                       GpTrainingReport& report) {
  const Eigen::Index n = data.x_unit.rows();
  const double best_subset_lml = *std::max_element(stage.lml.begin(), stage.lml.end());
  const std::vector<size_t> leader = basin_leaders(stage);
  std::vector<size_t> leaders;
  for (size_t s = 0; s < leader.size(); ++s) {
    if (leader[s] == s) leaders.push_back(s);
  }
  if (options.optimise) {
    progress.say(count_of(static_cast<long long>(leaders.size()), "start", "starts") + " on all " + std::to_string(n) + " points" +
                 (n > kSlowFitPoints ? " (a likelihood evaluation costs O(n^3): progress every " +
                                           std::to_string(static_cast<int>(options.progress_seconds)) + " s)"
                                     : std::string()));
  }
  for_each_parallel(leaders.size(), threads, [&](size_t i) {
    const size_t s = leaders[i];
    const auto t_start = std::chrono::steady_clock::now();
    GpStartReport& r = report.starts[s];
    LogMarginalLikelihood lml(data.x_unit, data.y, options.noise_term, known_noise, options.estimate_mean);
    const bool refine = options.optimise && (!stage.used || best_subset_lml - stage.lml[s] <= kHopelessSubsetGap);
    if (!refine) {
      const auto value = lml(stage.optima[s], false);
      r.final_log = stage.optima[s];
      r.evaluations = 1;
      r.ok = value.ok;
      r.log_marginal_likelihood = value.ok ? value.lml : kFailedLml;
      if (!value.ok) {
        r.outcome = value.reason;
      } else if (!options.optimise) {
        r.outcome = "fixed hyper-parameters";
      } else {
        std::ostringstream why;
        why << "not refined: its subset LML " << stage.lml[s] << " is " << best_subset_lml - stage.lml[s]
            << " below the best start's";
        r.outcome = why.str();
      }
    } else {
      const LocalOptimum optimum = maximise(lml, stage.optima[s], options, bounds, progress.enabled() ? &progress : nullptr,
                                            "start " + std::to_string(s));
      r.final_log = optimum.theta;
      r.log_marginal_likelihood = optimum.lml;
      r.evaluations = optimum.evaluations;
      r.outcome = optimum.outcome;
      r.ok = optimum.lml > kFailedLml;
    }
    r.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  });
  for (size_t s = 0; s < leader.size(); ++s) {
    if (leader[s] == s) continue;
    const GpStartReport& l = report.starts[leader[s]];
    GpStartReport& r = report.starts[s];
    r.final_log = l.final_log;
    r.log_marginal_likelihood = l.log_marginal_likelihood;
    r.ok = l.ok;
    r.outcome = "same basin as start " + std::to_string(leader[s]) + " on the subset; shares its optimum";
  }
}

// Climbs the (restricted) likelihood from every start (report.starts) and picks the best
// (report.best_start). Throws when no start gives a factorisable covariance.
void tune_hyper_parameters(const NormalisedData& data, const Eigen::VectorXd& known_noise, const GpTrainingOptions& options,
                           const LogBounds& bounds, const std::vector<Eigen::VectorXd>& starts, GpTrainingReport& report) {
  const int threads = options.threads > 0 ? options.threads : usable_cores();  // affinity and OMP_NUM_THREADS
  report.starts.resize(starts.size());
  for (size_t s = 0; s < starts.size(); ++s) {
    report.starts[s].initial_log = starts[s];
    report.starts[s].final_log = starts[s];
  }
  TrainingProgress progress(options.progress);
  const SubsetStage stage = climb_on_a_subset(data, known_noise, options, bounds, starts, threads, progress, report);
  climb_on_all_data(data, known_noise, options, bounds, stage, threads, progress, report);
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
}

// Factorises K at the chosen hyper-parameters, solves for α, estimates the constant mean when asked
// and fills the summary with the leave-one-out figures.
void fit_at_hyper_parameters(GaussianProcess::State& state, const NormalisedData& data, const GpTrainingOptions& options,
                             GpTrainingReport& report) {
  Eigen::MatrixXd kf;
  rbf_signal_covariance(data.x_unit, state.hyper, kf);
  const auto chol = cholesky_with_jitter(kf, state.hyper.noise_variance, state.cholesky, state.known_noise);
  if (!chol.ok) throw Error("Gaussian process fit failed at the optimum: " + chol.reason);
  state.jitter = chol.jitter;
  report.jitter = chol.jitter;
  state.alpha = state.cholesky.triangularView<Eigen::Lower>().solve(data.y);
  state.cholesky.triangularView<Eigen::Lower>().transpose().solveInPlace(state.alpha);
  if (options.estimate_mean) estimate_constant_mean(state);
  if (chol.jitter > 0.0) {
    std::ostringstream w;
    w << "jitter " << chol.jitter << " added to the covariance diagonal (" << chol.attempts
      << " factorisation attempts): inputs are nearly duplicated";
    report.warnings.push_back(w.str());
  }
  leave_one_out(state, state.summary);
}

// A leave-one-out error at least this fraction of the outputs' standard deviation: no better than their mean.
constexpr double kExplainsNothingFraction = 0.9;

// "… is at its lower/upper bound" for each optimised hyper-parameter within kAtBoundLog of one.
void warn_at_bounds(const Eigen::VectorXd& theta, const LogBounds& bounds, const TrainingSet& data,
                    const GpTrainingOptions& options, GpTrainingReport& report) {
  if (!options.optimise) return;
  auto at_bound = [&](Eigen::Index i, const std::string& name) {
    if (theta(i) - bounds.lo(i) < kAtBoundLog) report.warnings.push_back(name + " is at its lower bound");
    if (bounds.hi(i) - theta(i) < kAtBoundLog) report.warnings.push_back(name + " is at its upper bound");
  };
  const auto d = static_cast<Eigen::Index>(data.inputs.size());
  at_bound(0, "signal variance");
  for (Eigen::Index k = 0; k < d; ++k) at_bound(1 + k, "length scale of " + data.inputs[static_cast<size_t>(k)].name);
  if (options.noise_term) at_bound(d + 1, "noise variance");
}

// A fit whose leave-one-out error is nearly the data's own scatter predicts no better than their mean:
// all noise, no signal. Said, because an optimiser with few starts can settle there on data that do
// have a trend (a single start on 80 noisy samples of dry_default: log-likelihood -113.5 against +77.9
// with the default restarts, leave-one-out error 20 %).
void warn_if_it_explains_nothing(const GaussianProcess::State& state, const GpTrainingOptions& options,
                                 GpTrainingReport& report) {
  const double scatter = state.y_scale;  // the outputs' standard deviation
  if (!(scatter > 0.0) || state.x_train.rows() < 2) return;
  const double fraction = state.summary.loo_rmse / scatter;
  if (!(fraction >= kExplainsNothingFraction)) return;
  std::ostringstream w;
  w.precision(2);
  w << "the fit explains almost nothing: its leave-one-out error is " << fraction
    << " of the data's own scatter (1 would be their mean); noise variance " << state.hyper.noise_variance
    << " against signal variance " << state.hyper.signal_variance << " (normalised)"
    << (options.restarts < GpTrainingOptions{}.restarts ? "; with fewer starts than the default the optimiser may have "
                                                          "missed the optimum: try the default --restarts"
                                                        : "; the data may hold no trend a GP can see");
  report.warnings.push_back(w.str());
}

}  // namespace

GaussianProcess train_gaussian_process(const TrainingSet& data, const GpTrainingOptions& options,
                                       GpTrainingReport* report_out) {
  const auto t0 = std::chrono::steady_clock::now();
  GpTrainingReport report;
  GaussianProcess::State state;
  const NormalisedData normalised = prepare_training_data(data, options, state, report);
  const auto d = static_cast<Eigen::Index>(data.inputs.size());
  const LogBounds bounds = log_bounds(options.bounds, d, options.noise_term);
  tune_hyper_parameters(normalised, state.known_noise, options, bounds, starting_points(options, bounds, d), report);
  const auto& best = report.starts[static_cast<size_t>(report.best_start)];
  state.hyper = GpHyperParameters::from_log(best.final_log, d, options.noise_term);
  auto& summary = state.summary;
  summary.log_marginal_likelihood = best.log_marginal_likelihood;
  summary.starts = static_cast<long long>(report.starts.size());
  summary.best_start = report.best_start;
  summary.dataset_path = data.source_path;
  summary.dataset_sha256 = data.source_hash;
  summary.dataset_description = data.description;
  summary.code_version = code_version();
  summary.created_utc = utc_timestamp();
  fit_at_hyper_parameters(state, normalised, options, report);
  warn_at_bounds(best.final_log, bounds, data, options, report);
  warn_if_it_explains_nothing(state, options, report);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary.seconds = report.seconds;
  if (report_out) *report_out = report;
  return GaussianProcess(std::move(state));
}

}  // namespace mufric
