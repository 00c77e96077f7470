#include "surrogate/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/units.hpp"

namespace mufric {
namespace {

constexpr double kMinusInfinity = -std::numeric_limits<double>::infinity();
// Attempts per walker at drawing a start of finite posterior density from the prior.
constexpr int kStartAttempts = 10000;
// Added to the likelihood's covariance diagonal, μ² units: 1e-6 of the smallest measurement SD
// worth stating (0.001), so that a covariance singular to rounding still factorises.
constexpr double kCovarianceJitter = 1e-12;
constexpr const char* kAmplitudeName = "discrepancy_amplitude";
constexpr const char* kLengthScaleName = "discrepancy_length_scale";

// A standard normal from two uniforms (Box & Muller 1958), so that a seed gives the same draws on
// every standard library.
double standard_normal(std::mt19937_64& random) {
  const double u1 = 1.0 - uniform01(random());  // (0, 1]
  const double u2 = uniform01(random());
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

double draw_from(const Prior& prior, std::mt19937_64& random) {
  switch (prior.kind) {
    case PriorKind::uniform: return prior.a + (prior.b - prior.a) * uniform01(random());
    case PriorKind::normal: return prior.a + prior.b * standard_normal(random);
    case PriorKind::log_normal: return prior.a * std::exp(prior.b * standard_normal(random));
    case PriorKind::half_normal: return prior.a * std::abs(standard_normal(random));
  }
  return prior.a;
}

Prior parse_prior(const nlohmann::json& node, const std::string& where) {
  if (!node.is_object() || node.size() != 1) {
    throw Error(where + ": a prior is an object with one key, e.g. {\"uniform\": [0.2, 0.9]}");
  }
  // The one key and its value, taken from an iterator of `node` itself (a binding to *items().begin()
  // refers into the temporary proxy: a stack use after scope, which ASan found).
  const auto only = node.begin();
  const std::string word = only.key();
  const nlohmann::json& arguments = only.value();
  Prior prior;
  size_t expected = 2;
  if (word == "uniform") {
    prior.kind = PriorKind::uniform;
  } else if (word == "normal") {
    prior.kind = PriorKind::normal;
  } else if (word == "log_normal") {
    prior.kind = PriorKind::log_normal;
  } else if (word == "half_normal") {
    prior.kind = PriorKind::half_normal;
    expected = 1;
  } else {
    throw Error(where + "." + word + ": unknown prior (uniform, normal, log_normal, half_normal)");
  }
  const std::string key = where + "." + word;
  if (!arguments.is_array() || arguments.size() != expected) {
    throw Error(key + ": expects " + std::to_string(expected) + (expected == 1 ? " number" : " numbers") + " in a list");
  }
  for (const auto& argument : arguments) {
    if (!argument.is_number()) throw Error(key + ": " + argument.dump() + " is not a number");
  }
  prior.a = arguments[0].get<double>();
  if (expected == 2) prior.b = arguments[1].get<double>();
  prior.check(key);
  return prior;
}

}  // namespace

double quantile_of_sorted(const std::vector<double>& sorted, double probability) {
  const double position = probability * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, sorted.size() - 1);
  return sorted[below] + (position - static_cast<double>(below)) * (sorted[above] - sorted[below]);
}

std::string_view to_string(PriorKind kind) {
  switch (kind) {
    case PriorKind::uniform: return "uniform";
    case PriorKind::normal: return "normal";
    case PriorKind::log_normal: return "log_normal";
    case PriorKind::half_normal: return "half_normal";
  }
  return "?";
}

double Prior::log_density(double x) const {
  if (!std::isfinite(x)) return kMinusInfinity;
  switch (kind) {
    case PriorKind::uniform: return x >= a && x <= b ? 0.0 : kMinusInfinity;
    case PriorKind::normal: return -0.5 * ((x - a) / b) * ((x - a) / b);
    case PriorKind::log_normal: {
      if (x <= 0.0) return kMinusInfinity;
      const double z = (std::log(x) - std::log(a)) / b;
      return -0.5 * z * z - std::log(x);
    }
    case PriorKind::half_normal: return x >= 0.0 ? -0.5 * (x / a) * (x / a) : kMinusInfinity;
  }
  return kMinusInfinity;
}

std::string Prior::describe() const {
  std::ostringstream out;
  out << to_string(kind) << "(" << a;
  if (kind != PriorKind::half_normal) out << ", " << b;
  out << ")";
  return out.str();
}

void Prior::check(const std::string& where) const {
  const bool finite = std::isfinite(a) && std::isfinite(b);
  switch (kind) {
    case PriorKind::uniform:
      if (!finite || !(a < b)) throw Error(where + ": a uniform prior needs finite bounds lo < hi");
      return;
    case PriorKind::normal:
      if (!finite || !(b > 0)) throw Error(where + ": a normal prior needs a finite mean and a positive SD");
      return;
    case PriorKind::log_normal:
      if (!finite || !(a > 0) || !(b > 0)) throw Error(where + ": a log-normal prior needs a positive median and a positive SD of its log");
      return;
    case PriorKind::half_normal:
      if (!std::isfinite(a) || !(a > 0)) throw Error(where + ": a half-normal prior needs a positive scale");
      return;
  }
}

CalibrationPriors parse_calibration_priors(const std::string& json_text, const std::string& source) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(source + ": not JSON: " + e.what());
  }
  if (!root.is_object()) throw Error(source + ": a priors file is a JSON object");
  CalibrationPriors priors;
  for (const auto& [key, value] : root.items()) {
    if (key == "parameters") {
      if (!value.is_object()) throw Error(source + ": parameters: an object of input name → prior");
      for (const auto& [name, prior] : value.items()) {
        priors.parameters.emplace_back(name, parse_prior(prior, source + ": parameters." + name));
      }
    } else if (key == "discrepancy") {
      if (!value.is_object()) throw Error(source + ": discrepancy: an object (enabled, amplitude, length_scale)");
      for (const auto& [field, setting] : value.items()) {
        const std::string where = source + ": discrepancy." + field;
        if (field == "enabled") {
          if (!setting.is_boolean()) throw Error(where + ": true or false");
          priors.discrepancy = setting.get<bool>();
        } else if (field == "amplitude") {
          priors.discrepancy_amplitude = parse_prior(setting, where);
        } else if (field == "length_scale") {
          priors.discrepancy_length_scale = parse_prior(setting, where);
        } else {
          throw Error(where + ": unknown key (enabled, amplitude, length_scale)");
        }
      }
    } else {
      throw Error(source + ": " + key + ": unknown key (parameters, discrepancy)");
    }
  }
  return priors;
}

Measurements read_measurements(const std::string& path) {
  const CsvTable table = read_csv_table(path);
  table.column("mu");
  table.column("mu_sd");
  Measurements data;
  const auto n = static_cast<Eigen::Index>(table.rows.size());
  if (n == 0) throw Error(path + ": no measurements");
  std::vector<std::vector<double>> columns;
  for (const CsvColumn& c : table.columns) {
    if (c.name == "mu" || c.name == "mu_sd") continue;
    const KnownInput* known = find_known_input(c.name);
    if (known == nullptr) {
      throw Error(path + ": column '" + c.name + "' is not a model input (conditions: contact_pressure, sliding_velocity, "
                  "temperature, ...; values: mu, mu_sd)");
    }
    data.condition_names.push_back(c.name);
    columns.push_back(table.si_column(c.name, known->kind));
    for (size_t i = 0; i < columns.back().size(); ++i) {
      const std::string why = physical_range_violation(columns.back()[i], known->kind);
      if (!why.empty()) throw Error(path + ": line " + std::to_string(table.line_of_row[i]) + ", column '" + c.name + "': " + why);
    }
  }
  data.conditions.resize(n, static_cast<Eigen::Index>(columns.size()));
  for (size_t j = 0; j < columns.size(); ++j) {
    data.conditions.col(static_cast<Eigen::Index>(j)) = Eigen::Map<const Eigen::VectorXd>(columns[j].data(), n);
  }
  const std::vector<double> mu = table.si_column("mu", QuantityKind::dimensionless);
  const std::vector<double> sd = table.si_column("mu_sd", QuantityKind::dimensionless);
  data.mu = Eigen::Map<const Eigen::VectorXd>(mu.data(), n);
  data.mu_sd = Eigen::Map<const Eigen::VectorXd>(sd.data(), n);
  for (Eigen::Index i = 0; i < n; ++i) {
    data.row_names.push_back(path + " line " + std::to_string(table.line_of_row[static_cast<size_t>(i)]));
  }
  return data;
}

CalibrationProblem::CalibrationProblem(std::shared_ptr<const GaussianProcess> emulator, Measurements data,
                                       std::vector<std::string> parameters, CalibrationPriors priors)
    : emulator_(std::move(emulator)), data_(std::move(data)), parameters_(std::move(parameters)),
      priors_(std::move(priors)) {
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
  for (const std::string& condition : data_.condition_names) {
    const Eigen::Index column = column_of(condition);
    if (column < 0) throw Error("calibration: the measurements give '" + condition + "', which the model does not have (its inputs: " + names + ")");
    if (std::find(parameters_.begin(), parameters_.end(), condition) != parameters_.end()) {
      throw Error("calibration: '" + condition + "' is both measured and calibrated");
    }
    condition_column_.push_back(column);
  }
  for (size_t j = 0; j < inputs.size(); ++j) {
    const auto column = static_cast<Eigen::Index>(j);
    if (std::find(condition_column_.begin(), condition_column_.end(), column) == condition_column_.end() &&
        std::find(parameter_column_.begin(), parameter_column_.end(), column) == parameter_column_.end()) {
      throw Error("calibration: the model's input '" + inputs[j].name + "' is neither a measurement condition nor calibrated");
    }
  }
  const Eigen::Index n = data_.mu.size();
  if (n < 1) throw Error("calibration: no measurements");
  if (data_.conditions.rows() != n || data_.conditions.cols() != static_cast<Eigen::Index>(data_.condition_names.size()) ||
      data_.mu_sd.size() != n || static_cast<Eigen::Index>(data_.row_names.size()) != n) {
    throw Error("calibration: the measurements' conditions, μ, SD and row names differ in size");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::string& row = data_.row_names[static_cast<size_t>(i)];
    if (!std::isfinite(data_.mu(i))) throw Error(row + ": μ is not a finite number");
    if (!(std::isfinite(data_.mu_sd(i)) && data_.mu_sd(i) > 0.0)) {
      throw Error(row + ": the measurement's SD must be positive and finite (a measurement without scatter cannot be weighed)");
    }
    for (size_t c = 0; c < condition_column_.size(); ++c) {
      const InputSpec& input = inputs[static_cast<size_t>(condition_column_[c])];
      const double value = data_.conditions(i, static_cast<Eigen::Index>(c));
      if (!input.contains(value)) {
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
  names_ = parameters_;
  if (priors_.discrepancy) {
    names_.emplace_back(kAmplitudeName);
    names_.emplace_back(kLengthScaleName);
  }
  unit_data_conditions_ = unit_conditions(data_.conditions);
}

Eigen::MatrixXd CalibrationProblem::emulator_points(const Eigen::MatrixXd& conditions, const Eigen::VectorXd& theta) const {
  Eigen::MatrixXd points(conditions.rows(), static_cast<Eigen::Index>(emulator_->inputs().size()));
  for (size_t c = 0; c < condition_column_.size(); ++c) points.col(condition_column_[c]) = conditions.col(static_cast<Eigen::Index>(c));
  for (size_t k = 0; k < parameter_column_.size(); ++k) points.col(parameter_column_[k]).setConstant(theta(static_cast<Eigen::Index>(k)));
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
                                                           double amplitude, double length_scale) {
  return amplitude * amplitude * rbf_correlations(ua / length_scale, ub / length_scale);
}

double CalibrationProblem::log_posterior(const Eigen::VectorXd& coordinates) const {
  const Eigen::Index k = parameter_count();
  const Eigen::VectorXd theta = coordinates.head(k);
  double log_density = 0.0;
  for (Eigen::Index j = 0; j < k; ++j) {
    const InputSpec& input = emulator_->inputs()[static_cast<size_t>(parameter_column_[static_cast<size_t>(j)])];
    if (!input.contains(theta(j))) return kMinusInfinity;
    log_density += parameter_priors_[static_cast<size_t>(j)].log_density(theta(j));
  }
  double amplitude = 0.0, length_scale = 1.0;
  if (priors_.discrepancy) {
    // Sampled as logs: the prior's density of σ, ℓ times the Jacobian σ, ℓ.
    amplitude = std::exp(coordinates(k));
    length_scale = std::exp(coordinates(k + 1));
    log_density += priors_.discrepancy_amplitude.log_density(amplitude) + coordinates(k);
    log_density += priors_.discrepancy_length_scale.log_density(length_scale) + coordinates(k + 1);
  }
  if (!std::isfinite(log_density)) return kMinusInfinity;

  const Likelihood likelihood = likelihood_at(theta, amplitude, length_scale);
  if (likelihood.factor.info() != Eigen::Success) return kMinusInfinity;
  const Eigen::VectorXd whitened = likelihood.factor.matrixL().solve(likelihood.residual);
  const double log_determinant_half = likelihood.factor.matrixLLT().diagonal().array().log().sum();
  const double value = log_density - 0.5 * whitened.squaredNorm() - log_determinant_half;
  return std::isfinite(value) ? value : kMinusInfinity;
}

CalibrationProblem::Likelihood CalibrationProblem::likelihood_at(const Eigen::VectorXd& theta, double amplitude,
                                                                 double length_scale) const {
  Likelihood out;
  out.measured = emulator_->latent_points(emulator_points(data_.conditions, theta));
  Eigen::MatrixXd covariance = emulator_->latent_covariance(out.measured, out.measured);
  covariance.diagonal().array() += data_.mu_sd.array().square() + kCovarianceJitter;
  if (amplitude > 0.0) covariance += discrepancy_covariance(unit_data_conditions_, unit_data_conditions_, amplitude, length_scale);
  out.factor.compute(covariance);
  out.residual = data_.mu - out.measured.mean;
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
        coordinates(k) = std::log(draw_from(priors_.discrepancy_amplitude, random));
        coordinates(k + 1) = std::log(draw_from(priors_.discrepancy_length_scale, random));
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

CalibrationResult calibrate(const CalibrationProblem& problem, const EnsembleOptions& options, const SamplerProgress& progress) {
  const Eigen::MatrixXd start = problem.draw_start(options.walkers, options.seed);
  const EnsembleChains chains = run_ensemble_sampler(
      [&problem](const Eigen::VectorXd& c) { return problem.log_posterior(c); }, start, options, progress);
  CalibrationResult result;
  result.options = options;
  result.acceptance = chains.acceptance;
  result.diagnostics = diagnose_chains(chains);
  result.convergence_failure = convergence_failure(result.diagnostics, problem.coordinate_names(), chains.steps());
  result.samples = chains.pooled();
  if (problem.discrepancy()) result.samples.rightCols(2) = result.samples.rightCols(2).array().exp().matrix();
  for (Eigen::Index j = 0; j < problem.dimension(); ++j) {
    std::vector<double> values(result.samples.col(j).data(), result.samples.col(j).data() + result.samples.rows());
    std::sort(values.begin(), values.end());
    ParameterSummary s;
    s.name = problem.coordinate_names()[static_cast<size_t>(j)];
    s.mean = result.samples.col(j).mean();
    s.sd = std::sqrt((result.samples.col(j).array() - s.mean).square().sum() / static_cast<double>(values.size() - 1));
    s.lo95 = quantile_of_sorted(values, 0.025);
    s.median = quantile_of_sorted(values, 0.5);
    s.hi95 = quantile_of_sorted(values, 0.975);
    s.split_rhat = result.diagnostics.split_rhat(j);
    s.effective_sample_size = result.diagnostics.effective_sample_size(j);
    result.summary.push_back(s);
  }
  return result;
}

CalibratedPosterior::CalibratedPosterior(std::shared_ptr<const CalibrationProblem> problem, const Eigen::MatrixXd& samples,
                                         Eigen::Index thinned)
    : problem_(std::move(problem)) {
  const Eigen::Index total = samples.rows();
  if (total < 1) throw Error("calibrated prediction: no posterior samples");
  if (samples.cols() != problem_->dimension()) {
    throw Error("calibrated prediction: posterior samples have " + std::to_string(samples.cols()) + " coordinates for " +
                std::to_string(problem_->dimension()));
  }
  const Eigen::Index used = std::max<Eigen::Index>(1, std::min(thinned, total));
  const Eigen::Index k = problem_->parameter_count();
  kept_.resize(used, samples.cols());
  for (Eigen::Index s = 0; s < used; ++s) {
    // Evenly spaced through the pooled samples (walker by walker), so every walker contributes.
    kept_.row(s) = samples.row(s * total / used);
    Sample sample;
    sample.theta = kept_.row(s).head(k).transpose();
    if (problem_->discrepancy()) {
      sample.amplitude = kept_(s, k);
      sample.length_scale = kept_(s, k + 1);
    }
    sample.likelihood = problem_->likelihood_at(sample.theta, sample.amplitude, sample.length_scale);
    if (sample.likelihood.factor.info() != Eigen::Success) {
      throw Error("calibrated prediction: the likelihood's covariance at posterior sample " + std::to_string(s) +
                  " is not positive definite");
    }
    sample.weights = sample.likelihood.factor.solve(sample.likelihood.residual);
    samples_.push_back(std::move(sample));
  }
}

CalibratedPrediction CalibratedPosterior::predict(const Eigen::MatrixXd& conditions, int max_threads) const {
  const Eigen::Index q = conditions.rows();
  CalibratedPrediction out;
  for (Eigen::VectorXd* v : {&out.mean, &out.sd, &out.discrepancy_mean, &out.discrepancy_sd, &out.parameter_sd,
                             &out.emulator_sd, &out.conditional_sd}) {
    v->resize(q);
  }
  for (Eigen::Index first = 0; first < q; first += kPredictionBlockRows) {
    const Eigen::Index count = std::min(kPredictionBlockRows, q - first);
    predict_block(conditions.middleRows(first, count), first, max_threads, out);
  }
  return out;
}

void CalibratedPosterior::predict_block(const Eigen::MatrixXd& conditions, Eigen::Index first, int max_threads,
                                        CalibratedPrediction& out) const {
  const CalibrationProblem& problem = *problem_;
  const GaussianProcess& emulator = problem.emulator();
  const Eigen::Index q = conditions.rows(), used = static_cast<Eigen::Index>(samples_.size());
  const Eigen::MatrixXd unit_new = problem.unit_conditions(conditions);
  const Eigen::MatrixXd& unit_data = problem.unit_data_conditions();
  Eigen::MatrixXd means(q, used), variances(q, used), discrepancy_means(q, used), discrepancy_variances(q, used),
      emulator_variances(q, used);
  auto predict_sample = [&](Eigen::Index s) {
    const Sample& sample = samples_[static_cast<size_t>(s)];
    const auto lower = sample.likelihood.factor.matrixL();
    const GaussianProcess::LatentPoints at = emulator.latent_points(problem.emulator_points(conditions, sample.theta));
    // ζ(x) = η(x, θ) + δ(x) given y (KOH eq. 6): cov(η(x), y) = C_η(x, X), cov(δ(x), y) = K_δ(x, X).
    // diag(A C⁻¹ Aᵀ) = |L⁻¹Aᵀ|² per column, with C = LLᵀ the likelihood's factor.
    const Eigen::MatrixXd emulator_cross = emulator.latent_covariance(at, sample.likelihood.measured);
    const Eigen::MatrixXd emulator_explained = lower.solve(emulator_cross.transpose());
    const double discrepancy_variance = sample.amplitude * sample.amplitude;
    const Eigen::VectorXd prior_emulator_variance = emulator.latent_variance(at);
    emulator_variances.col(s) = prior_emulator_variance - emulator_explained.colwise().squaredNorm().transpose();
    if (problem.discrepancy()) {
      const Eigen::MatrixXd discrepancy_cross =
          CalibrationProblem::discrepancy_covariance(unit_new, unit_data, sample.amplitude, sample.length_scale);
      const Eigen::MatrixXd discrepancy_explained = lower.solve(discrepancy_cross.transpose());
      discrepancy_means.col(s) = discrepancy_cross * sample.weights;
      discrepancy_variances.col(s) =
          (discrepancy_variance - discrepancy_explained.colwise().squaredNorm().array()).transpose().matrix();
      means.col(s) = at.mean + emulator_cross * sample.weights + discrepancy_means.col(s);
      variances.col(s) = prior_emulator_variance.array() + discrepancy_variance -
                         (emulator_explained + discrepancy_explained).colwise().squaredNorm().transpose().array();
    } else {
      discrepancy_means.col(s).setZero();
      discrepancy_variances.col(s).setZero();
      means.col(s) = at.mean + emulator_cross * sample.weights;
      variances.col(s) = emulator_variances.col(s);
    }
  };
  // Each sample writes its own columns: the threads share nothing but what they read.
  const int team = evaluation_team_size(max_threads);
#pragma omp parallel for num_threads(team) schedule(static) if (team > 1)
  for (Eigen::Index s = 0; s < used; ++s) predict_sample(s);

  // A mixture's moments: the mean of the means; the mean variance plus the variance of the means.
  auto spread = [used](const Eigen::MatrixXd& m) {
    const Eigen::VectorXd centre = m.rowwise().mean();
    return Eigen::VectorXd(((m.colwise() - centre).array().square().rowwise().sum() / static_cast<double>(used)).matrix());
  };
  const Eigen::VectorXd between = spread(means);
  const Eigen::VectorXd within = variances.rowwise().mean().cwiseMax(0.0);
  out.mean.segment(first, q) = means.rowwise().mean();
  out.parameter_sd.segment(first, q) = between.cwiseSqrt();
  out.sd.segment(first, q) = (within + between).cwiseSqrt();
  out.conditional_sd.segment(first, q) = within.cwiseSqrt();
  out.emulator_sd.segment(first, q) = emulator_variances.rowwise().mean().cwiseMax(0.0).cwiseSqrt();
  out.discrepancy_mean.segment(first, q) = discrepancy_means.rowwise().mean();
  out.discrepancy_sd.segment(first, q) =
      (discrepancy_variances.rowwise().mean().cwiseMax(0.0) + spread(discrepancy_means)).cwiseSqrt();
}

CalibratedPrediction predict_calibrated(const CalibrationProblem& problem, const CalibrationResult& result,
                                        const Eigen::MatrixXd& conditions, Eigen::Index thinned) {
  // Not owned: the posterior lives only for this call.
  const std::shared_ptr<const CalibrationProblem> borrowed(&problem, [](const CalibrationProblem*) {});
  return CalibratedPosterior(borrowed, result.samples, thinned).predict(conditions);
}

}  // namespace mufric
