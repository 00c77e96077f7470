#pragma once
// Hyper-parameter fitting by maximising the log marginal likelihood (R&W eq. 2.30, gradient
// eq. 5.9) with NLopt's bounded L-BFGS from several deterministic starts.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "common/dataset_file.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// Bounds on the hyper-parameters (not their logs), in normalised-output and unit-box units.
struct GpBounds {
  double signal_variance_lo = 1e-3, signal_variance_hi = 1e5;
  double length_scale_lo = 1e-2, length_scale_hi = 1e3;
  double noise_variance_lo = 1e-6, noise_variance_hi = 1e-1;
};

struct GpTrainingOptions {
  int restarts = 4;            // starts after the first, as scikit-learn's n_restarts_optimizer
  std::uint64_t seed = 0;      // restarts are drawn log-uniformly in the bounds from this seed
  bool noise_term = true;
  GpBounds bounds;
  GpHyperParameters initial;   // first start; empty length_scales → 0.5 box widths, σ² = 1, σn² = 1e-5
  int max_evaluations = 1000;  // per start and stage
  // Each start first optimises on a random subset of this many points when n > 2 × subset_size
  // (0: never), then on all data.
  Eigen::Index subset_size = 256;
  double relative_tolerance = 1e-9;  // on the LML (≈ scipy L-BFGS-B's default factr 1e7)
  // Absolute LML change that ends a run: a likelihood ratio of e^1e-5 is statistically void, and
  // near the optimum the LML's own rounding noise is of this size.
  double absolute_tolerance = 1e-5;
  int threads = 0;             // starts run in parallel; 0 = all cores
  bool optimise = true;        // false: use `initial` as given
  // Put each sample's own variance (μ_std²) on the covariance diagonal, beside the learned noise.
  // Right when the samples' errors are independent; a dataset whose samples share their tool draws
  // (common random numbers: every plan row uses the same phases and seeds) has errors correlated
  // across samples, which the diagonal would wrongly smooth away. Needs every sample's μ_std.
  bool sample_noise = false;
  // The served interval is the latent mean's alone (IntervalMeaning::mean_over_draws): for samples
  // whose errors are independent, on the diagonal (stochastic kriging) or in the learned noise (one
  // draw per sample). micro_std_error is then 0.
  bool interval_of_mean = false;
  // Estimate the constant mean by generalised least squares and charge its variance to every
  // interval (ordinary kriging, GaussianProcess::State::mean_estimated); false: the samples' average
  // is the known mean (simple kriging, as scikit-learn's normalize_y).
  bool estimate_mean = false;
  // Progress lines for long fits (thread-safe calls): when each stage starts, and during a start's
  // full-data climb at most every kTrainingProgressSeconds. May be empty.
  std::function<void(const std::string&)> progress;
  double progress_seconds = 10.0;  // between two lines of one start's climb (see below)
};

// progress_seconds: a fit of 10 000 points spends tens of seconds per LML evaluation, and printed
// nothing for minutes (issue 30); a line every 10 s says it is alive and what an evaluation costs.

struct GpStartReport {
  Eigen::VectorXd initial_log;
  Eigen::VectorXd final_log;
  double log_marginal_likelihood = 0.0;
  int evaluations = 0;         // full-data LML evaluations
  int subset_evaluations = 0;  // evaluations of the subset stage (each ~(n/m)³ cheaper)
  std::string outcome;  // NLopt's result, or why the start failed
  double seconds = 0.0;
  bool ok = false;
};

struct GpTrainingReport {
  std::vector<GpStartReport> starts;
  int best_start = -1;
  double jitter = 0.0;
  double seconds = 0.0;
  std::vector<std::string> warnings;  // constant outputs, parameter at a bound, jitter added, ...
  bool sample_noise_used = false;     // per-sample variances on the diagonal
  double micro_std_error = 0.0;       // RMS μ standard error of the training samples (0: none)
};

// Log marginal likelihood of normalised outputs y at unit-box inputs, and its gradient w.r.t. θ.
class LogMarginalLikelihood {
 public:
  // known_noise: per-point variance on the diagonal (normalised), or empty. restricted: the
  // likelihood of the data's contrasts, free of an unknown constant mean (REML, Patterson & Thompson
  // 1971; Santner, Williams & Notz 2003, section 3.3): what an estimated mean is fitted with, since
  // plain ML with the mean estimated biases σ² low by the mean's own variance, worst at a few samples.
  LogMarginalLikelihood(const Eigen::MatrixXd& x_unit, const Eigen::VectorXd& y, bool noise_term,
                        Eigen::VectorXd known_noise = Eigen::VectorXd(), bool restricted = false);

  struct Value {
    bool ok = false;
    double lml = 0.0;
    Eigen::VectorXd gradient;  // w.r.t. θ = log hyper-parameters
    double jitter = 0.0;
    std::string reason;
  };
  Value operator()(const Eigen::VectorXd& theta, bool with_gradient);

  // Factor and α at θ (for the final model); valid after a successful call.
  const Eigen::MatrixXd& signal_covariance() const { return kf_; }

 private:
  const Eigen::MatrixXd& x_unit_;
  const Eigen::VectorXd& y_;
  bool noise_term_;
  Eigen::VectorXd known_noise_;
  bool restricted_;
  Eigen::MatrixXd kf_;      // σ² R, lower triangle
  Eigen::MatrixXd factor_;  // L, then (LLᵀ)⁻¹
  Eigen::MatrixXd scaled_;  // x_unit / l
};

// Fits a GP to the training set. Throws Error with a clear reason when no start succeeds.
GaussianProcess train_gaussian_process(const TrainingSet& data, const GpTrainingOptions& options,
                                       GpTrainingReport* report = nullptr);

// Leave-one-out figures in closed form from K⁻¹ (R&W eq. 5.12): μ₋ᵢ = yᵢ − αᵢ/[K⁻¹]ᵢᵢ, σ²₋ᵢ = 1/[K⁻¹]ᵢᵢ;
// with an estimated mean, re-estimated without the point: K⁻¹ becomes P = K⁻¹ − K⁻¹11ᵀK⁻¹/1ᵀK⁻¹1 and
// α = Py (Dubrule 1983, Math. Geol. 15(6):687, for universal kriging).
void leave_one_out(const GaussianProcess::State& state, GpTrainingSummary& summary);
// The same per training point: each point's LOO error (μ − μ₋ᵢ, μ units) and LOO standard deviation,
// in the order of state.x_train; empty when the factor cannot be inverted or there is one point.
struct LeaveOneOut {
  Eigen::VectorXd error, std;
};
LeaveOneOut leave_one_out_points(const GaussianProcess::State& state);

}  // namespace mufric
