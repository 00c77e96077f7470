#pragma once
// Bayesian calibration of a simulator's parameters θ through its GP emulator (Kennedy & O'Hagan
// 2001, J. R. Stat. Soc. B 63:425, eq. 5; the emulator's joint posterior in the likelihood as in
// Higdon et al. 2004, SIAM J. Sci. Comput. 26:448, §2):
//
//   y_i = η(x_i, θ) + δ(x_i) + ε_i,   ε_i ~ N(0, s_i²),   δ ~ GP(0, σ_δ² exp(−½ |u − u'|² / ℓ_δ²)),
//
// x the measurement's conditions (contact pressure, sliding velocity, temperature), u their unit-box
// coordinates in the emulator's box, s_i the measurement's own standard deviation. With η's GP
// posterior (mean m, covariance C_η: the interval of the mean over the roughness draws),
//
//   y | θ, σ_δ, ℓ_δ ~ N(m(X, θ), C_η(X, θ) + K_δ(X) + diag(s²)),
//
// and the posterior of (θ, σ_δ, ℓ_δ) is sampled with the ensemble sampler. δ can be switched off
// (σ_δ = 0): then θ alone must explain the data within the measurement's and the emulator's errors.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "surrogate/ensemble_sampler.hpp"
#include "surrogate/gaussian_process.hpp"

namespace mufric {

// Measured friction at n conditions.
struct Measurements {
  std::vector<std::string> condition_names;  // model inputs they fix, e.g. contact_pressure, sliding_velocity
  Eigen::MatrixXd conditions;                // n × c, SI
  Eigen::VectorXd mu;                        // measured μ
  Eigen::VectorXd mu_sd;                     // its standard deviation (the measurement's own scatter), > 0
  std::vector<std::string> row_names;        // for messages and provenance: "friction.csv row 4"
};

// A measurement file: a CSV (common/csv_table.hpp) with a column per condition, named as the
// model's input with its unit ("contact_pressure[MPa],sliding_velocity[m/min],temperature[C]"), and
// "mu" and "mu_sd" (the measurement's standard deviation); '#' lines carry the provenance. Rows are
// named "FILE line N". Errors name the file, line and column.
Measurements read_measurements(const std::string& path);

// A prior on one scalar: uniform on [a, b]; normal of mean a and SD b; log-normal of median a and
// SD b of its log; half-normal of scale a (on x ≥ 0).
enum class PriorKind { uniform, normal, log_normal, half_normal };
struct Prior {
  PriorKind kind = PriorKind::uniform;
  double a = 0.0, b = 0.0;
  // Unnormalised log density; −∞ outside the support.
  double log_density(double x) const;
  // "uniform(0.2, 0.9)", "normal(0.4, 0.1)", ...
  std::string describe() const;
  // Throws Error starting with `where` when a, b do not make a proper prior.
  void check(const std::string& where) const;
};
std::string_view to_string(PriorKind kind);

struct CalibrationPriors {
  // The calibrated inputs' priors by input name (SI). One not named: uniform over its box. Every
  // prior is cut to the emulator's box: the emulator knows nothing outside it.
  std::vector<std::pair<std::string, Prior>> parameters;
  bool discrepancy = false;
  // σ_δ in μ units: half-normal of scale 0.05 (a discrepancy of a few hundredths of μ is plausible,
  // one of 0.3 is not). ℓ_δ in unit-box widths: log-normal of median 0.5, so that δ is smooth over
  // the box and does not fit each measurement on its own.
  Prior discrepancy_amplitude{PriorKind::half_normal, 0.05, 0.0};
  Prior discrepancy_length_scale{PriorKind::log_normal, 0.5, 0.7};
};
// A priors file (JSON), e.g.
//   {"parameters": {"shear_factor": {"uniform": [0.2, 0.9]}, "adhesive_coefficient": {"normal": [0.4, 0.1]}},
//    "discrepancy": {"enabled": true, "amplitude": {"half_normal": [0.05]}, "length_scale": {"log_normal": [0.5, 0.7]}}}
// Errors name the source and the key.
CalibrationPriors parse_calibration_priors(const std::string& json_text, const std::string& source);

// The posterior's coordinates: θ in SI (one per calibrated input), then, with δ on, log σ_δ and log ℓ_δ.
class CalibrationProblem {
 public:
  // `parameters`: the emulator's inputs that are calibrated; every other input must be a
  // measurement condition. Refuses (Error naming the row, input or name) a measurement outside the
  // emulator's box, a condition the emulator does not have, an input neither measured nor
  // calibrated, a non-positive or non-finite SD, a prior for an input that is not calibrated.
  CalibrationProblem(std::shared_ptr<const GaussianProcess> emulator, Measurements data,
                     std::vector<std::string> parameters, CalibrationPriors priors);

  Eigen::Index dimension() const { return static_cast<Eigen::Index>(names_.size()); }
  // Calibrated input names, then "discrepancy_amplitude", "discrepancy_length_scale" with δ on.
  const std::vector<std::string>& coordinate_names() const { return names_; }
  Eigen::Index parameter_count() const { return static_cast<Eigen::Index>(parameters_.size()); }
  const Measurements& data() const { return data_; }
  const GaussianProcess& emulator() const { return *emulator_; }
  bool discrepancy() const { return priors_.discrepancy; }
  const Prior& prior_of(Eigen::Index parameter) const { return parameter_priors_[static_cast<size_t>(parameter)]; }

  // log p(coordinates | y) up to a constant; −∞ outside the prior's support or where the
  // likelihood's covariance is not positive definite.
  double log_posterior(const Eigen::VectorXd& coordinates) const;
  // Walkers drawn from the prior (within the box), each of finite posterior density.
  Eigen::MatrixXd draw_start(int walkers, std::uint64_t seed) const;
  // The emulator's input rows for these conditions (n × c, the measurements' order) at θ.
  Eigen::MatrixXd emulator_points(const Eigen::MatrixXd& conditions, const Eigen::VectorXd& theta) const;
  // Unit-box coordinates of conditions in the emulator's box (δ's inputs).
  Eigen::MatrixXd unit_conditions(const Eigen::MatrixXd& conditions) const;
  // The likelihood at θ and δ's (σ_δ, ℓ_δ): the emulator's latent posterior at the measured
  // conditions (its rows' correlations with the campaign, kept for predictions), the Cholesky factor
  // of C_η + K_δ + diag(s²) and the residual y − m (σ_δ = 0: no δ). The factor's info() says whether
  // the covariance was positive definite.
  struct Likelihood {
    GaussianProcess::LatentPoints measured;
    Eigen::LLT<Eigen::MatrixXd> factor;
    Eigen::VectorXd residual;
  };
  Likelihood likelihood_at(const Eigen::VectorXd& theta, double amplitude, double length_scale) const;
  const Eigen::MatrixXd& unit_data_conditions() const { return unit_data_conditions_; }
  // σ_δ² exp(−½ |u − u'|²/ℓ_δ²) between two sets of unit-box conditions.
  static Eigen::MatrixXd discrepancy_covariance(const Eigen::MatrixXd& ua, const Eigen::MatrixXd& ub,
                                                double amplitude, double length_scale);

 private:
  std::shared_ptr<const GaussianProcess> emulator_;
  Measurements data_;
  std::vector<std::string> parameters_, names_;
  CalibrationPriors priors_;
  std::vector<Prior> parameter_priors_;
  std::vector<Eigen::Index> condition_column_;  // emulator column of each measurement condition
  std::vector<Eigen::Index> parameter_column_;  // emulator column of each calibrated input
  Eigen::MatrixXd unit_data_conditions_;        // the measurements' conditions, unit box
};

struct ParameterSummary {
  std::string name;
  double mean = 0.0, sd = 0.0, lo95 = 0.0, hi95 = 0.0, median = 0.0;  // natural units (SI; σ_δ, ℓ_δ themselves)
  double split_rhat = 0.0, effective_sample_size = 0.0;
};

struct CalibrationResult {
  std::vector<ParameterSummary> summary;
  Eigen::MatrixXd samples;  // pooled kept states, natural units (σ_δ, ℓ_δ, not their logs)
  double acceptance = 0.0;
  ChainDiagnostics diagnostics;
  // "" when the chains meet the limits (ensemble_sampler.hpp), else why not, naming the coordinate.
  std::string convergence_failure;
  EnsembleOptions options;
};

// One quantile of sorted values, by linear interpolation between order statistics (Hyndman & Fan
// 1996, definition 7, R's default).
double quantile_of_sorted(const std::vector<double>& sorted, double probability);

CalibrationResult calibrate(const CalibrationProblem& problem, const EnsembleOptions& options,
                            const SamplerProgress& progress = {});

// The calibrated prediction at conditions (rows, SI), averaged over posterior samples: per sample
// the latent truth ζ = η(x, θ) + δ(x) conditioned on the measurements (KOH eq. 6), then mean and
// variance of the mixture. The parts of its variance, each on its own (they need not add up: given
// y, η and δ are correlated):
struct CalibratedPrediction {
  Eigen::VectorXd mean, sd;
  Eigen::VectorXd discrepancy_mean, discrepancy_sd;  // δ's posterior alone (0 with δ off)
  Eigen::VectorXd parameter_sd;  // the spread of the per-sample means: θ's (and δ's hyper-parameters') share
  Eigen::VectorXd emulator_sd;   // η's own given y: the campaign's interval of the mean over roughness draws
  // √E_s[v_s]: η + δ given y and θ, so that sd² = parameter_sd² + conditional_sd² exactly.
  Eigen::VectorXd conditional_sd;
};

// The posterior predictive of a calibration: per posterior sample (θ, σ_δ, ℓ_δ) the likelihood's
// factor and weights, computed once, so that predictions at new conditions cost a cross-covariance
// and two triangular solves per sample. Safe to call from many threads at once.
class CalibratedPosterior {
 public:
  // `samples`: posterior states in natural units (CalibrationResult::samples' layout); `thinned`
  // evenly spaced rows of them are kept (walker by walker, so every walker contributes). Throws
  // Error when a sample's likelihood covariance is not positive definite.
  CalibratedPosterior(std::shared_ptr<const CalibrationProblem> problem, const Eigen::MatrixXd& samples,
                      Eigen::Index thinned = kDefaultThinnedSamples);
  static constexpr Eigen::Index kDefaultThinnedSamples = 200;

  // In blocks of kPredictionBlockRows conditions (memory bounded whatever the batch), the samples
  // of a block shared among max_threads threads (0: as many as OpenMP allows; evaluation_team_size).
  CalibratedPrediction predict(const Eigen::MatrixXd& conditions, int max_threads = 0) const;
  static constexpr Eigen::Index kPredictionBlockRows = 256;
  const CalibrationProblem& problem() const { return *problem_; }
  // The kept samples, one row each (natural units).
  const Eigen::MatrixXd& samples() const { return kept_; }

 private:
  struct Sample {
    Eigen::VectorXd theta;
    double amplitude = 0.0, length_scale = 1.0;
    CalibrationProblem::Likelihood likelihood;
    Eigen::VectorXd weights;  // (C_η + K_δ + diag s²)⁻¹ (y − m)
  };
  // Rows [first, first + conditions.rows()) of out, from every kept sample.
  void predict_block(const Eigen::MatrixXd& conditions, Eigen::Index first, int max_threads, CalibratedPrediction& out) const;

  std::shared_ptr<const CalibrationProblem> problem_;
  Eigen::MatrixXd kept_;
  std::vector<Sample> samples_;
};

// CalibratedPosterior(problem, result.samples, thinned).predict(conditions), for a single use.
CalibratedPrediction predict_calibrated(const CalibrationProblem& problem, const CalibrationResult& result,
                                        const Eigen::MatrixXd& conditions,
                                        Eigen::Index thinned = CalibratedPosterior::kDefaultThinnedSamples);

}  // namespace mufric
