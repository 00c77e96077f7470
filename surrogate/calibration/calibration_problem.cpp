#include "surrogate/calibration/calibration_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "common/error.hpp"
#include "common/units.hpp"

namespace mufric {

const InputSpec& input_of(const GaussianProcess& model, const std::string& name) {
  std::string names;
  for (const InputSpec& input : model.inputs()) {
    if (input.name == name) return input;
    if (!names.empty()) names += ", ";
    names += input.name;
  }
  throw Error("calibration: the model has no input '" + name + "' (its inputs: " + names + ")");
}
namespace {

// Attempts per walker at drawing a start of finite posterior density from the prior.
constexpr int kStartAttempts = 10000;
// Added to the likelihood's covariance diagonal, μ² units: 1e-6 of the smallest measurement SD
// worth stating (0.001), so that a covariance singular to rounding still factorises.
constexpr double kCovarianceJitter = 1e-12;
constexpr const char* kAmplitudeName = "discrepancy_amplitude";
constexpr const char* kLengthScaleName = "discrepancy_length_scale";

}  // namespace

CalibrationProblem::CalibrationProblem(std::shared_ptr<const GaussianProcess> emulator, Measurements data,
                                       std::vector<std::string> parameters, CalibrationPriors priors,
                                       std::vector<std::pair<std::string, double>> held)
    : emulator_(std::move(emulator)), data_(completed(std::move(data))), parameters_(std::move(parameters)),
      priors_(std::move(priors)), held_(std::move(held)) {
  const InputSpace& inputs = emulator_->inputs();
  auto column_of = [&](const std::string& name) -> Eigen::Index {
    for (size_t j = 0; j < inputs.size(); ++j) {
      if (inputs[j].name == name) return static_cast<Eigen::Index>(j);
    }
    return -1;
  };
  std::string names;
  for (const InputSpec& input : inputs) names += (names.empty() ? "" : ", ") + input.name;
  if (parameters_.empty()) throw Error("calibration: no input is calibrated (the model's inputs: " + names + ")");
  for (const std::string& parameter : parameters_) {
    const Eigen::Index column = column_of(parameter);
    if (column < 0) throw Error("calibration: the model has no input '" + parameter + "' to calibrate (its inputs: " + names + ")");
    parameter_column_.push_back(column);
  }
  for (const auto& [name, value] : held_) {
    const Eigen::Index column = column_of(name);
    if (column < 0) throw Error("calibration: the model has no input '" + name + "' to hold (its inputs: " + names + ")");
    const InputSpec& input = inputs[static_cast<size_t>(column)];
    if (!input.contains(value)) {
      throw Error("calibration: " + name + " held at " + format_human(value, input.kind()) + ", outside the model's box " +
                  format_human(input.lo, input.kind()) + " – " + format_human(input.hi, input.kind()));
    }
    held_column_.push_back(column);
  }
  for (const std::string& condition : data_.condition_names) {
    const Eigen::Index column = column_of(condition);
    if (column < 0) throw Error("calibration: the measurements give '" + condition + "', which the model does not have (its inputs: " + names + ")");
    if (std::find(parameters_.begin(), parameters_.end(), condition) != parameters_.end()) {
      throw Error("calibration: '" + condition + "' is both measured and calibrated");
    }
    if (std::find(held_column_.begin(), held_column_.end(), column) != held_column_.end()) {
      throw Error("calibration: '" + condition + "' is both measured and held");
    }
    condition_column_.push_back(column);
  }
  for (size_t j = 0; j < inputs.size(); ++j) {
    const auto column = static_cast<Eigen::Index>(j);
    auto in = [column](const std::vector<Eigen::Index>& v) { return std::find(v.begin(), v.end(), column) != v.end(); };
    if (!in(condition_column_) && !in(parameter_column_) && !in(held_column_)) {
      throw Error("calibration: the model's input '" + inputs[j].name + "' is neither a measurement condition, held nor calibrated");
    }
  }
  const Eigen::Index n = data_.mu.size();
  if (n < 1) throw Error("calibration: no measurements");
  const auto c = static_cast<Eigen::Index>(data_.condition_names.size());
  if (data_.conditions.rows() != n || data_.conditions.cols() != c || data_.mu_sd.size() != n ||
      static_cast<Eigen::Index>(data_.row_names.size()) != n || data_.condition_sd.rows() != n ||
      data_.condition_sd.cols() != c || data_.condition_half_width.rows() != n || data_.condition_half_width.cols() != c ||
      static_cast<Eigen::Index>(data_.data_set_of_row.size()) != n) {
    throw Error("calibration: the measurements' conditions, uncertainties, μ, SD, row names and data sets differ in size");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::string& row = data_.row_names[static_cast<size_t>(i)];
    if (!std::isfinite(data_.mu(i))) throw Error(row + ": μ is not a finite number");
    if (!(std::isfinite(data_.mu_sd(i)) && data_.mu_sd(i) > 0.0)) {
      throw Error(row + ": the measurement's SD must be positive and finite (a measurement without scatter cannot be weighed)");
    }
    const int set = data_.data_set_of_row[static_cast<size_t>(i)];
    if (set < 0 || set >= static_cast<int>(data_.data_sets.size())) throw Error(row + ": no data set");
    for (Eigen::Index j = 0; j < c; ++j) {
      const InputSpec& input = inputs[static_cast<size_t>(condition_column_[static_cast<size_t>(j)])];
      const double value = data_.conditions(i, j);
      if (data_.uncertain(i, j)) {
        const Prior prior = data_.condition_prior(i, j);
        if (prior.mass_within(input.lo, input.hi) <= 0.0) {
          throw Error(row + ": " + input.name + " " + prior.describe(input.kind()) + " lies wholly outside the model's box " +
                      format_human(input.lo, input.kind()) + " – " + format_human(input.hi, input.kind()) +
                      " (the emulator knows nothing there: run the campaign over it, or leave the row out)");
        }
        latent_cells_.emplace_back(i, j);
        latent_priors_.push_back(prior);
      } else if (!input.contains(value)) {
        throw Error(row + ": " + input.name + " " + format_human(value, input.kind()) + " lies outside the model's box " +
                    format_human(input.lo, input.kind()) + " – " + format_human(input.hi, input.kind()) +
                    " (the emulator knows nothing there: run the campaign over it, or leave the row out)");
      }
    }
  }
  for (const auto& [name, prior] : priors_.parameters) {
    if (std::find(parameters_.begin(), parameters_.end(), name) == parameters_.end()) {
      throw Error("calibration: a prior is given for '" + name + "', which is not calibrated");
    }
  }
  for (size_t k = 0; k < parameters_.size(); ++k) {
    const InputSpec& input = inputs[static_cast<size_t>(parameter_column_[k])];
    Prior prior{PriorKind::uniform, input.lo, input.hi};
    for (const auto& [name, given] : priors_.parameters) {
      if (name == parameters_[k]) prior = given;
    }
    parameter_priors_.push_back(prior);
  }
  for (const auto& [name, prior] : priors_.biases) {
    const auto found = std::find(data_.data_sets.begin(), data_.data_sets.end(), name);
    if (found == data_.data_sets.end()) {
      std::string sets;
      for (const std::string& s : data_.data_sets) sets += (sets.empty() ? "" : ", ") + s;
      throw Error("calibration: a bias is given for data set '" + name + "', which is not among the measurements' (" + sets + ")");
    }
    bias_sets_.push_back(static_cast<int>(found - data_.data_sets.begin()));
    bias_priors_.push_back(prior);
  }
  if (!(priors_.discrepancy_trend_sd >= 0.0 && std::isfinite(priors_.discrepancy_trend_sd))) {
    throw Error("calibration: the discrepancy's trend SD must be a number >= 0");
  }
  if (priors_.discrepancy_trend_sd > 0.0 && !priors_.discrepancy) {
    throw Error("calibration: a discrepancy trend is given with the discrepancy off (--discrepancy, or \"enabled\": true)");
  }
  names_ = parameters_;
  if (priors_.discrepancy) {
    names_.emplace_back(kAmplitudeName);
    names_.emplace_back(kLengthScaleName);
  }
  for (const int set : bias_sets_) names_.push_back("bias[" + data_.data_sets[static_cast<size_t>(set)] + "]");
  for (const auto& [row, condition] : latent_cells_) {
    names_.push_back(data_.condition_names[static_cast<size_t>(condition)] + " (" + data_.row_names[static_cast<size_t>(row)] + ")");
  }
}

Eigen::MatrixXd CalibrationProblem::emulator_points(const Eigen::MatrixXd& conditions, const Eigen::VectorXd& theta) const {
  Eigen::MatrixXd points(conditions.rows(), static_cast<Eigen::Index>(emulator_->inputs().size()));
  for (size_t c = 0; c < condition_column_.size(); ++c) points.col(condition_column_[c]) = conditions.col(static_cast<Eigen::Index>(c));
  for (size_t k = 0; k < parameter_column_.size(); ++k) points.col(parameter_column_[k]).setConstant(theta(static_cast<Eigen::Index>(k)));
  for (size_t h = 0; h < held_column_.size(); ++h) points.col(held_column_[h]).setConstant(held_[h].second);
  return points;
}

Eigen::MatrixXd CalibrationProblem::unit_conditions(const Eigen::MatrixXd& conditions) const {
  Eigen::MatrixXd unit(conditions.rows(), conditions.cols());
  for (size_t c = 0; c < condition_column_.size(); ++c) {
    const InputSpec& input = emulator_->inputs()[static_cast<size_t>(condition_column_[c])];
    unit.col(static_cast<Eigen::Index>(c)) = (conditions.col(static_cast<Eigen::Index>(c)).array() - input.lo) / (input.hi - input.lo);
  }
  return unit;
}

Eigen::MatrixXd CalibrationProblem::discrepancy_covariance(const Eigen::MatrixXd& ua, const Eigen::MatrixXd& ub,
                                                           double amplitude, double length_scale, double trend_sd) {
  Eigen::MatrixXd covariance = amplitude * amplitude * rbf_correlations(ua / length_scale, ub / length_scale);
  if (trend_sd > 0.0) {
    const Eigen::MatrixXd centred_a = ua.array() - 0.5, centred_b = ub.array() - 0.5;
    covariance.array() += trend_sd * trend_sd * (1.0 + (centred_a * centred_b.transpose()).array());
  }
  return covariance;
}

Eigen::VectorXd CalibrationProblem::discrepancy_variance(const Eigen::MatrixXd& u, double amplitude, double trend_sd) {
  Eigen::VectorXd variance = Eigen::VectorXd::Constant(u.rows(), amplitude * amplitude);
  if (trend_sd > 0.0) variance.array() += trend_sd * trend_sd * (1.0 + (u.array() - 0.5).square().rowwise().sum());
  return variance;
}

QuantityKind CalibrationProblem::coordinate_kind(Eigen::Index j) const {
  if (j < parameter_count()) return kind_of_input(parameters_[static_cast<size_t>(j)]);
  if (j >= latent_offset() && j < dimension()) {
    const Eigen::Index condition = latent_cells_[static_cast<size_t>(j - latent_offset())].second;
    return kind_of_input(data_.condition_names[static_cast<size_t>(condition)]);
  }
  return QuantityKind::dimensionless;
}

PosteriorPoint CalibrationProblem::point_at(const Eigen::VectorXd& natural) const {
  PosteriorPoint point;
  point.theta = natural.head(parameter_count());
  if (discrepancy()) {
    point.amplitude = natural(discrepancy_offset());
    point.length_scale = natural(discrepancy_offset() + 1);
  }
  point.biases = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(data_.data_sets.size()));
  for (Eigen::Index b = 0; b < bias_count(); ++b) point.biases(bias_sets_[static_cast<size_t>(b)]) = natural(bias_offset() + b);
  point.conditions = data_.conditions;
  for (Eigen::Index l = 0; l < latent_count(); ++l) {
    const auto& [row, condition] = latent_cells_[static_cast<size_t>(l)];
    point.conditions(row, condition) = natural(latent_offset() + l);
  }
  return point;
}

double CalibrationProblem::log_posterior(const Eigen::VectorXd& coordinates) const {
  const Eigen::Index k = parameter_count();
  double log_density = 0.0;
  for (Eigen::Index j = 0; j < k; ++j) {
    const InputSpec& input = emulator_->inputs()[static_cast<size_t>(parameter_column_[static_cast<size_t>(j)])];
    if (!input.contains(coordinates(j))) return kLogZeroDensity;
    log_density += parameter_priors_[static_cast<size_t>(j)].log_density(coordinates(j));
  }
  Eigen::VectorXd natural = coordinates;
  if (priors_.discrepancy) {
    // Sampled as logs: the prior's density of σ, ℓ times the Jacobian σ, ℓ.
    const Eigen::Index d = discrepancy_offset();
    natural(d) = std::exp(coordinates(d));
    natural(d + 1) = std::exp(coordinates(d + 1));
    log_density += priors_.discrepancy_amplitude.log_density(natural(d)) + coordinates(d);
    log_density += priors_.discrepancy_length_scale.log_density(natural(d + 1)) + coordinates(d + 1);
  }
  for (Eigen::Index b = 0; b < bias_count(); ++b) {
    log_density += bias_priors_[static_cast<size_t>(b)].log_density(coordinates(bias_offset() + b));
  }
  for (Eigen::Index l = 0; l < latent_count(); ++l) {
    const double value = coordinates(latent_offset() + l);
    const Eigen::Index condition = latent_cells_[static_cast<size_t>(l)].second;
    if (!emulator_->inputs()[static_cast<size_t>(condition_column_[static_cast<size_t>(condition)])].contains(value)) {
      return kLogZeroDensity;  // the emulator knows nothing there: the prior is cut to the box
    }
    log_density += latent_priors_[static_cast<size_t>(l)].log_density(value);
  }
  if (!std::isfinite(log_density)) return kLogZeroDensity;

  const Likelihood likelihood = likelihood_at(point_at(natural));
  if (likelihood.factor.info() != Eigen::Success) return kLogZeroDensity;
  const Eigen::VectorXd whitened = likelihood.factor.matrixL().solve(likelihood.residual);
  const double log_determinant_half = likelihood.factor.matrixLLT().diagonal().array().log().sum();
  const double value = log_density - 0.5 * whitened.squaredNorm() - log_determinant_half;
  return std::isfinite(value) ? value : kLogZeroDensity;
}

CalibrationProblem::Likelihood CalibrationProblem::likelihood_at(const PosteriorPoint& point) const {
  Likelihood out;
  out.measured = emulator_->latent_points(emulator_points(point.conditions, point.theta));
  out.unit_conditions = unit_conditions(point.conditions);
  Eigen::MatrixXd covariance = emulator_->latent_covariance(out.measured, out.measured);
  covariance.diagonal().array() += data_.mu_sd.array().square() + kCovarianceJitter;
  if (point.amplitude > 0.0) {
    covariance += discrepancy_covariance(out.unit_conditions, out.unit_conditions, point.amplitude, point.length_scale,
                                         priors_.discrepancy_trend_sd);
  }
  out.factor.compute(covariance);
  out.residual = data_.mu - out.measured.mean;
  for (Eigen::Index i = 0; i < out.residual.size(); ++i) out.residual(i) -= point.biases(data_.data_set_of_row[static_cast<size_t>(i)]);
  return out;
}

Eigen::MatrixXd CalibrationProblem::draw_start(int walkers, std::uint64_t seed) const {
  std::mt19937_64 random(seed);
  const Eigen::Index k = parameter_count();
  Eigen::MatrixXd start(walkers, dimension());
  for (int w = 0; w < walkers; ++w) {
    bool found = false;
    for (int attempt = 0; attempt < kStartAttempts && !found; ++attempt) {
      Eigen::VectorXd coordinates(dimension());
      for (Eigen::Index j = 0; j < k; ++j) coordinates(j) = draw_from(parameter_priors_[static_cast<size_t>(j)], random);
      if (priors_.discrepancy) {
        coordinates(discrepancy_offset()) = std::log(draw_from(priors_.discrepancy_amplitude, random));
        coordinates(discrepancy_offset() + 1) = std::log(draw_from(priors_.discrepancy_length_scale, random));
      }
      for (Eigen::Index b = 0; b < bias_count(); ++b) {
        coordinates(bias_offset() + b) = draw_from(bias_priors_[static_cast<size_t>(b)], random);
      }
      for (Eigen::Index l = 0; l < latent_count(); ++l) {
        coordinates(latent_offset() + l) = draw_from(latent_priors_[static_cast<size_t>(l)], random);
      }
      if (std::isfinite(log_posterior(coordinates))) {
        start.row(w) = coordinates.transpose();
        found = true;
      }
    }
    if (!found) {
      throw Error("calibration: no draw from the priors within the model's box has a finite posterior density (" +
                  std::to_string(kStartAttempts) + " tried): a prior that lies outside the box?");
    }
  }
  return start;
}

}  // namespace mufric
