#pragma once
// Bayesian calibration of a simulator's parameters θ through its GP emulator (Kennedy & O'Hagan
// 2001, J. R. Stat. Soc. B 63:425, eq. 5; the emulator's joint posterior in the likelihood as in
// Higdon et al. 2004, SIAM J. Sci. Comput. 26:448, §2):
//
//   y_i = η(x_i, θ) + δ(x_i) + b_{k(i)} + ε_i,   ε_i ~ N(0, s_i²),   δ ~ GP(0, σ_δ² exp(−½ |u − u'|² / ℓ_δ²)),
//
// x the measurement's conditions (contact pressure, sliding velocity, temperature), u their unit-box
// coordinates in the emulator's box, s_i the measurement's own standard deviation, b_k the bias of
// data set k (a set that measures something else than the reference, e.g. a tribometer's μ beside
// a cut's rake-face μ; 0 for a set given no bias). With η's GP posterior (mean m, covariance C_η:
// the interval of the mean over the roughness draws),
//
//   y | θ, σ_δ, ℓ_δ, b, x ~ N(m(X, θ) + b, C_η(X, θ) + K_δ(X) + diag(s²)),
//
// and the posterior of (θ, σ_δ, ℓ_δ, b) is sampled with the ensemble sampler. δ can be switched off
// (σ_δ = 0): then θ alone must explain the data within the measurement's and the emulator's errors.
// A condition known only within an uncertainty (an interface temperature estimated by a model) is a
// latent coordinate of its own with that uncertainty as its prior, sampled with the rest (errors in
// variables: the structural approach, Carroll, Ruppert, Stefanski & Crainiceanu, Measurement Error
// in Nonlinear Models, 2nd ed. 2006, ch. 9).
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "common/units.hpp"
#include "surrogate/ensemble_sampler.hpp"
#include "surrogate/gaussian_process.hpp"

namespace mufric {

// A prior on one scalar: uniform on [a, b]; normal of mean a and SD b; log-normal of median a and
// SD b of its log; half-normal of scale a (on x ≥ 0).
enum class PriorKind { uniform, normal, log_normal, half_normal };
struct Prior {
  PriorKind kind = PriorKind::uniform;
  double a = 0.0, b = 0.0;
  // Unnormalised log density; −∞ outside the support.
  double log_density(double x) const;
  // "uniform(0.2, 0.9)", "normal(0.4, 0.1)", ... in the prior's own (SI) numbers.
  std::string describe() const;
  // The same in the human unit of a kind of quantity: "normal(500 °C, 50 K)" for a temperature.
  std::string describe(QuantityKind quantity) const;
  // The prior's probability of [lo, hi] (1 for a prior wholly inside).
  double mass_within(double lo, double hi) const;
  // Throws Error starting with `where` when a, b do not make a proper prior.
  void check(const std::string& where) const;
};
std::string_view to_string(PriorKind kind);

// Measured friction at n conditions, from one or several data sets (files).
struct Measurements {
  std::vector<std::string> condition_names;  // model inputs they fix, e.g. contact_pressure, sliding_velocity
  Eigen::MatrixXd conditions;                // n × c, SI: each condition's stated value (its mean or range's middle)
  // A condition known only within an uncertainty, per cell (SI): a normal's SD or a uniform range's
  // half-width, at most one of them positive; both 0 (or the matrices left empty): known exactly.
  Eigen::MatrixXd condition_sd, condition_half_width;
  Eigen::VectorXd mu;                        // measured μ
  Eigen::VectorXd mu_sd;                     // its standard deviation (the measurement's own scatter), > 0
  std::vector<std::string> row_names;        // for messages and provenance: "friction.csv line 4"
  // Each row's data set (an index into data_sets; empty: one set, "measurements").
  std::vector<std::string> data_sets;
  std::vector<int> data_set_of_row;

  Eigen::Index rows() const { return mu.size(); }
  bool uncertain(Eigen::Index row, Eigen::Index condition) const;
  // The prior of the true value of cell (row, condition): normal(stated, sd) or uniform(stated ± half-width).
  Prior condition_prior(Eigen::Index row, Eigen::Index condition) const;
};
// The same measurements with every optional part sized: uncertainty matrices of zeros, one data set.
Measurements completed(Measurements data);
// One data set after another (each file one set, named by the file's stem; equal names get a suffix).
// Every set must give the same conditions (in any column order): the error names the set and the
// condition it lacks.
Measurements combine_measurement_sets(const std::vector<Measurements>& sets);

// A measurement file: a CSV (common/csv_table.hpp) with a column per condition, named as the
// model's input with its unit ("contact_pressure[MPa],sliding_velocity[m/min],temperature[C]"), and
// "mu" and "mu_sd" (the measurement's standard deviation); '#' lines carry the provenance. A
// condition may come with its uncertainty: "temperature_sd[C]" (a normal SD; 0 in a row: known
// exactly) or "temperature_min[C]" and "temperature_max[C]" (a uniform range; the value column may
// then be left out). Rows are named "FILE line N"; the file is one data set, named by its stem.
// Errors name the file, line and column.
Measurements read_measurements(const std::string& path);

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
  // δ's linear trend, marginalised: δ(x) = β₀ + βᵀ(u − ½) + GP with β₀, βⱼ ~ N(0, s²) independent
  // (KOH 2001 §4.3's regression mean h(x)ᵀβ under a normal prior, which adds s²(1 + (u − ½)ᵀ(u' − ½))
  // to δ's covariance; Rasmussen & Williams §2.7); u in widths of the emulator's box. s in μ units
  // (an offset at the box centre, a change per box width); 0: no trend.
  double discrepancy_trend_sd = 0.0;
  // Data sets (by name) that carry a bias b_k of their own, with its prior (μ units); the others none.
  std::vector<std::pair<std::string, Prior>> biases;
};
// A priors file (JSON), e.g.
//   {"parameters": {"shear_factor": {"uniform": [0.2, 0.9]}, "adhesive_coefficient": {"normal": [0.4, 0.1]}},
//    "discrepancy": {"enabled": true, "amplitude": {"half_normal": [0.05]}, "length_scale": {"log_normal": [0.5, 0.7]},
//                    "trend_sd": 0.15},
//    "data_sets": {"tribometer": {"bias": {"normal": [0, 0.1]}}}}
// Errors name the source and the key.
CalibrationPriors parse_calibration_priors(const std::string& json_text, const std::string& source);

// One point of the posterior in natural units: θ, δ's hyper-parameters, each data set's bias (0 for
// a set without one) and the measured rows' true conditions (the stated values where exact).
struct PosteriorPoint {
  Eigen::VectorXd theta;
  double amplitude = 0.0, length_scale = 1.0;
  Eigen::VectorXd biases;      // per data set
  Eigen::MatrixXd conditions;  // n × c, SI
};

// The posterior's coordinates, in this order: θ in SI (one per calibrated input); with δ on, σ_δ and
// ℓ_δ (sampled as their logs, reported as themselves); one bias per data set given one; one true
// value per uncertain condition cell (SI), named "temperature (FILE line N)".
class CalibrationProblem {
 public:
  // `parameters`: the emulator's inputs that are calibrated; `held`: inputs at one value for every
  // measurement (a coefficient held by --fix); every other input must be a measurement condition.
  // Refuses (Error naming the row, input or name) a measurement outside the emulator's box (an
  // uncertain one: whose prior has no mass inside), a condition the emulator does not have, an input
  // neither measured, held nor calibrated, a non-positive or non-finite SD, a prior for an input that
  // is not calibrated, a bias for a data set that is not there.
  CalibrationProblem(std::shared_ptr<const GaussianProcess> emulator, Measurements data,
                     std::vector<std::string> parameters, CalibrationPriors priors,
                     std::vector<std::pair<std::string, double>> held = {});

  Eigen::Index dimension() const { return static_cast<Eigen::Index>(names_.size()); }
  const std::vector<std::string>& coordinate_names() const { return names_; }
  Eigen::Index parameter_count() const { return static_cast<Eigen::Index>(parameters_.size()); }
  const std::vector<std::string>& parameters() const { return parameters_; }
  // Where each group of coordinates starts, and how many.
  Eigen::Index discrepancy_offset() const { return parameter_count(); }
  Eigen::Index bias_offset() const { return parameter_count() + (discrepancy() ? 2 : 0); }
  Eigen::Index bias_count() const { return static_cast<Eigen::Index>(bias_sets_.size()); }
  Eigen::Index latent_offset() const { return bias_offset() + bias_count(); }
  Eigen::Index latent_count() const { return static_cast<Eigen::Index>(latent_cells_.size()); }
  const Measurements& data() const { return data_; }
  const GaussianProcess& emulator() const { return *emulator_; }
  const std::shared_ptr<const GaussianProcess>& emulator_pointer() const { return emulator_; }
  const CalibrationPriors& priors() const { return priors_; }
  const std::vector<std::pair<std::string, double>>& held() const { return held_; }
  bool discrepancy() const { return priors_.discrepancy; }
  const Prior& prior_of(Eigen::Index parameter) const { return parameter_priors_[static_cast<size_t>(parameter)]; }
  // The data set (index) of each bias coordinate, and the (row, condition) of each latent one.
  const std::vector<int>& bias_sets() const { return bias_sets_; }
  const std::vector<std::pair<Eigen::Index, Eigen::Index>>& latent_cells() const { return latent_cells_; }
  // The kind of quantity of coordinate j, for printing it in its unit: a coefficient's or a latent
  // condition's input kind; δ's and the biases' dimensionless.
  QuantityKind coordinate_kind(Eigen::Index j) const;

  // The point of natural coordinates (a row of CalibrationResult::samples).
  PosteriorPoint point_at(const Eigen::VectorXd& natural) const;
  // log p(coordinates | y) up to a constant, coordinates as sampled (δ's as logs); −∞ outside the
  // prior's support (a θ or a latent condition outside the box) or where the likelihood's covariance
  // is not positive definite.
  double log_posterior(const Eigen::VectorXd& coordinates) const;
  // Walkers drawn from the prior (within the box), each of finite posterior density.
  Eigen::MatrixXd draw_start(int walkers, std::uint64_t seed) const;
  // The emulator's input rows for these conditions (n × c, the measurements' order) at θ.
  Eigen::MatrixXd emulator_points(const Eigen::MatrixXd& conditions, const Eigen::VectorXd& theta) const;
  // Unit-box coordinates of conditions in the emulator's box (δ's inputs).
  Eigen::MatrixXd unit_conditions(const Eigen::MatrixXd& conditions) const;
  // The likelihood at a point: the emulator's latent posterior at the measured rows' conditions (its
  // rows' correlations with the campaign, kept for predictions), those conditions in the unit box
  // (δ's inputs), the Cholesky factor of C_η + K_δ + diag(s²) and the residual y − m − b (σ_δ = 0:
  // no δ). The factor's info() says whether the covariance was positive definite.
  struct Likelihood {
    GaussianProcess::LatentPoints measured;
    Eigen::MatrixXd unit_conditions;
    Eigen::LLT<Eigen::MatrixXd> factor;
    Eigen::VectorXd residual;
  };
  Likelihood likelihood_at(const PosteriorPoint& point) const;
  // σ_δ² exp(−½ |u − u'|²/ℓ_δ²) + s²(1 + (u − ½)ᵀ(u' − ½)) between two sets of unit-box conditions
  // (s: the priors' discrepancy_trend_sd), and its diagonal at one set.
  static Eigen::MatrixXd discrepancy_covariance(const Eigen::MatrixXd& ua, const Eigen::MatrixXd& ub, double amplitude,
                                                double length_scale, double trend_sd);
  static Eigen::VectorXd discrepancy_variance(const Eigen::MatrixXd& u, double amplitude, double trend_sd);

 private:
  std::shared_ptr<const GaussianProcess> emulator_;
  Measurements data_;
  std::vector<std::string> parameters_, names_;
  CalibrationPriors priors_;
  std::vector<std::pair<std::string, double>> held_;
  std::vector<Prior> parameter_priors_;
  std::vector<Eigen::Index> condition_column_;  // emulator column of each measurement condition
  std::vector<Eigen::Index> parameter_column_;  // emulator column of each calibrated input
  std::vector<Eigen::Index> held_column_;       // emulator column of each held input
  std::vector<int> bias_sets_;
  std::vector<Prior> bias_priors_;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> latent_cells_;
  std::vector<Prior> latent_priors_;
};

struct ParameterSummary {
  std::string name;
  double mean = 0.0, sd = 0.0, lo95 = 0.0, hi95 = 0.0, median = 0.0;  // natural units (SI; σ_δ, ℓ_δ themselves)
  double split_rhat = 0.0, effective_sample_size = 0.0;
};

struct CalibrationResult {
  std::vector<ParameterSummary> summary;  // per coordinate
  Eigen::MatrixXd samples;  // pooled kept states, natural units (σ_δ, ℓ_δ, not their logs)
  double acceptance = 0.0;
  ChainDiagnostics diagnostics;
  // "" when the chains meet the limits (ensemble_sampler.hpp), else why not, naming the coordinate.
  std::string convergence_failure;
  // As run: after a continuation (EnsembleOptions::max_steps) the steps kept and the burn-in before them.
  EnsembleOptions options;
};

// One quantile of sorted values, by linear interpolation between order statistics (Hyndman & Fan
// 1996, definition 7, R's default).
double quantile_of_sorted(const std::vector<double>& sorted, double probability);

// Samples the problem's posterior: stretch moves over every coordinate, the latent conditions with
// the rest (per-row Metropolis-within-Gibbs blocks for them were measured no faster for θ, whose
// mixing sets the run's length: bench/RESULTS.md, "Conditions with uncertainty").
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

  // In blocks of exactly kPredictionBlockRows conditions (the last one padded with copies of its
  // last row), the samples of a block shared among max_threads threads (0: as many as OpenMP allows;
  // evaluation_team_size). Every product then has the same shapes whatever the batch, so a point's
  // answer is the same bits alone, in any batch and on any team; the memory is bounded too.
  CalibratedPrediction predict(const Eigen::MatrixXd& conditions, int max_threads = 0) const;
  static constexpr Eigen::Index kPredictionBlockRows = 16;
  const CalibrationProblem& problem() const { return *problem_; }
  // The kept samples, one row each (natural units).
  const Eigen::MatrixXd& samples() const { return kept_; }

 private:
  struct Sample {
    PosteriorPoint point;
    CalibrationProblem::Likelihood likelihood;
    Eigen::VectorXd weights;  // (C_η + K_δ + diag s²)⁻¹ (y − m − b)
  };
  // Rows [first, first + count) of out from every kept sample, for the first count rows of a block
  // of kPredictionBlockRows conditions.
  void predict_block(const Eigen::MatrixXd& block, Eigen::Index count, Eigen::Index first, int max_threads,
                     CalibratedPrediction& out) const;

  std::shared_ptr<const CalibrationProblem> problem_;
  Eigen::MatrixXd kept_;
  std::vector<Sample> samples_;
};

// CalibratedPosterior(problem, result.samples, thinned).predict(conditions), for a single use.
CalibratedPrediction predict_calibrated(const CalibrationProblem& problem, const CalibrationResult& result,
                                        const Eigen::MatrixXd& conditions,
                                        Eigen::Index thinned = CalibratedPosterior::kDefaultThinnedSamples);

}  // namespace mufric
