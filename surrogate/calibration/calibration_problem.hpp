#pragma once
// The calibration's posterior as a density to sample (surrogate/calibration/calibration.hpp has the
// model): its coordinates, priors, likelihood and a start for the walkers.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "common/units.hpp"
#include "surrogate/calibration/measurements.hpp"
#include "surrogate/calibration/priors.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// The emulator's input called `name`; Error naming the inputs it has when there is none.
const InputSpec& input_of(const GaussianProcess& model, const std::string& name);

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

}  // namespace mufric
