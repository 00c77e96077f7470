#include "surrogate/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/blas_threads.hpp"
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

namespace {
double standard_normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
}  // namespace

std::string Prior::describe(QuantityKind quantity) const {
  if (quantity == QuantityKind::dimensionless) return describe();
  switch (kind) {
    case PriorKind::uniform: return "uniform(" + format_human(a, quantity) + ", " + format_human(b, quantity) + ")";
    case PriorKind::normal: return "normal(" + format_human(a, quantity) + ", sd " + format_human_difference(b, quantity) + ")";
    case PriorKind::log_normal: {
      std::ostringstream sd;
      sd << b;
      return "log_normal(median " + format_human(a, quantity) + ", sd of log " + sd.str() + ")";
    }
    case PriorKind::half_normal: return "half_normal(" + format_human_difference(a, quantity) + ")";
  }
  return describe();
}

double Prior::mass_within(double lo, double hi) const {
  if (!(hi > lo)) return 0.0;
  switch (kind) {
    case PriorKind::uniform: return std::max(0.0, std::min(hi, b) - std::max(lo, a)) / (b - a);
    case PriorKind::normal: return standard_normal_cdf((hi - a) / b) - standard_normal_cdf((lo - a) / b);
    case PriorKind::log_normal: {
      if (hi <= 0.0) return 0.0;
      const double below = lo <= 0.0 ? 0.0 : standard_normal_cdf((std::log(lo) - std::log(a)) / b);
      return standard_normal_cdf((std::log(hi) - std::log(a)) / b) - below;
    }
    case PriorKind::half_normal: {
      if (hi <= 0.0) return 0.0;
      return 2.0 * (standard_normal_cdf(hi / a) - standard_normal_cdf(std::max(lo, 0.0) / a));
    }
  }
  return 0.0;
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
      if (!value.is_object()) throw Error(source + ": discrepancy: an object (enabled, amplitude, length_scale, trend_sd)");
      for (const auto& [field, setting] : value.items()) {
        const std::string where = source + ": discrepancy." + field;
        if (field == "enabled") {
          if (!setting.is_boolean()) throw Error(where + ": true or false");
          priors.discrepancy = setting.get<bool>();
        } else if (field == "amplitude") {
          priors.discrepancy_amplitude = parse_prior(setting, where);
        } else if (field == "length_scale") {
          priors.discrepancy_length_scale = parse_prior(setting, where);
        } else if (field == "trend_sd") {
          if (!setting.is_number() || !std::isfinite(setting.get<double>()) || setting.get<double>() < 0.0) {
            throw Error(where + ": a number >= 0 (mu units; 0: no trend)");
          }
          priors.discrepancy_trend_sd = setting.get<double>();
        } else {
          throw Error(where + ": unknown key (enabled, amplitude, length_scale, trend_sd)");
        }
      }
    } else if (key == "data_sets") {
      if (!value.is_object()) throw Error(source + ": data_sets: an object of data set name → {\"bias\": prior}");
      for (const auto& [name, setting] : value.items()) {
        const std::string where = source + ": data_sets." + name;
        if (!setting.is_object()) throw Error(where + ": an object, e.g. {\"bias\": {\"normal\": [0, 0.1]}}");
        for (const auto& [field, prior] : setting.items()) {
          if (field != "bias") throw Error(where + "." + field + ": unknown key (bias)");
          priors.biases.emplace_back(name, parse_prior(prior, where + ".bias"));
        }
      }
    } else {
      throw Error(source + ": " + key + ": unknown key (parameters, discrepancy, data_sets)");
    }
  }
  return priors;
}

bool Measurements::uncertain(Eigen::Index row, Eigen::Index condition) const {
  return (condition_sd.size() > 0 && condition_sd(row, condition) > 0.0) ||
         (condition_half_width.size() > 0 && condition_half_width(row, condition) > 0.0);
}

Prior Measurements::condition_prior(Eigen::Index row, Eigen::Index condition) const {
  const double stated = conditions(row, condition);
  if (condition_sd.size() > 0 && condition_sd(row, condition) > 0.0) return {PriorKind::normal, stated, condition_sd(row, condition)};
  const double half = condition_half_width.size() > 0 ? condition_half_width(row, condition) : 0.0;
  return {PriorKind::uniform, stated - half, stated + half};
}

Measurements completed(Measurements data) {
  const Eigen::Index n = data.mu.size(), c = data.conditions.cols();
  if (data.condition_sd.size() == 0) data.condition_sd = Eigen::MatrixXd::Zero(n, c);
  if (data.condition_half_width.size() == 0) data.condition_half_width = Eigen::MatrixXd::Zero(n, c);
  if (data.data_sets.empty()) {
    data.data_sets = {"measurements"};
    data.data_set_of_row.assign(static_cast<size_t>(n), 0);
  }
  return data;
}

Measurements combine_measurement_sets(const std::vector<Measurements>& sets) {
  if (sets.empty()) throw Error("calibration: no measurements");
  Measurements all;
  all.condition_names = sets.front().condition_names;
  const auto c = static_cast<Eigen::Index>(all.condition_names.size());
  Eigen::Index n = 0;
  for (const Measurements& set : sets) n += set.mu.size();
  all.conditions.resize(n, c);
  all.condition_sd.resize(n, c);
  all.condition_half_width.resize(n, c);
  all.mu.resize(n);
  all.mu_sd.resize(n);
  Eigen::Index at = 0;
  for (const Measurements& given : sets) {
    const Measurements set = completed(given);
    const Eigen::Index rows = set.mu.size();
    for (size_t k = 0; k < set.data_sets.size(); ++k) {
      std::string name = set.data_sets[k];
      for (int suffix = 2; std::find(all.data_sets.begin(), all.data_sets.end(), name) != all.data_sets.end(); ++suffix) {
        name = set.data_sets[k] + "_" + std::to_string(suffix);
      }
      all.data_sets.push_back(name);
    }
    const int first_set = static_cast<int>(all.data_sets.size() - set.data_sets.size());
    for (Eigen::Index j = 0; j < c; ++j) {
      const std::string& name = all.condition_names[static_cast<size_t>(j)];
      const auto found = std::find(set.condition_names.begin(), set.condition_names.end(), name);
      if (found == set.condition_names.end()) {
        throw Error("calibration: data set '" + all.data_sets[static_cast<size_t>(first_set)] + "' gives no " + name +
                    ", which '" + all.data_sets.front() + "' gives: every data set must give the same conditions");
      }
      const auto column = static_cast<Eigen::Index>(found - set.condition_names.begin());
      all.conditions.block(at, j, rows, 1) = set.conditions.col(column);
      all.condition_sd.block(at, j, rows, 1) = set.condition_sd.col(column);
      all.condition_half_width.block(at, j, rows, 1) = set.condition_half_width.col(column);
    }
    if (set.condition_names.size() != all.condition_names.size()) {
      for (const std::string& name : set.condition_names) {
        if (std::find(all.condition_names.begin(), all.condition_names.end(), name) == all.condition_names.end()) {
          throw Error("calibration: data set '" + all.data_sets[static_cast<size_t>(first_set)] + "' gives " + name +
                      ", which '" + all.data_sets.front() + "' does not: every data set must give the same conditions");
        }
      }
    }
    all.mu.segment(at, rows) = set.mu;
    all.mu_sd.segment(at, rows) = set.mu_sd;
    all.row_names.insert(all.row_names.end(), set.row_names.begin(), set.row_names.end());
    for (const int k : set.data_set_of_row) all.data_set_of_row.push_back(first_set + k);
    at += rows;
  }
  return all;
}

Measurements read_measurements(const std::string& path) {
  const CsvTable table = read_csv_table(path);
  table.column("mu");
  table.column("mu_sd");
  Measurements data;
  const auto n = static_cast<Eigen::Index>(table.rows.size());
  if (n == 0) throw Error(path + ": no measurements");
  auto where = [&](size_t row, const std::string& column) {
    return path + ": line " + std::to_string(table.line_of_row[row]) + ", column '" + column + "'";
  };
  // Each column is a condition's value, SD, minimum or maximum: "temperature", "temperature_sd", ...
  auto split = [](const std::string& name) -> std::pair<std::string, std::string> {
    for (const char* suffix : {"_sd", "_min", "_max"}) {
      const std::string s = suffix;
      if (name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0) {
        return {name.substr(0, name.size() - s.size()), s.substr(1)};
      }
    }
    return {name, ""};
  };
  std::vector<std::string> names;
  for (const CsvColumn& c : table.columns) {
    if (c.name == "mu" || c.name == "mu_sd") continue;
    const auto [condition, part] = split(c.name);
    const KnownInput* known = find_known_input(condition);
    if (known == nullptr) {
      throw Error(path + ": column '" + c.name + "' is not a model input (conditions: contact_pressure, sliding_velocity, "
                  "temperature, ...; with _sd, or _min and _max, for their uncertainty; values: mu, mu_sd)");
    }
    if (std::find(names.begin(), names.end(), condition) == names.end()) names.push_back(condition);
  }
  const auto c = static_cast<Eigen::Index>(names.size());
  data.condition_names = names;
  data.conditions.resize(n, c);
  data.condition_sd = Eigen::MatrixXd::Zero(n, c);
  data.condition_half_width = Eigen::MatrixXd::Zero(n, c);
  for (Eigen::Index j = 0; j < c; ++j) {
    const std::string& name = names[static_cast<size_t>(j)];
    const QuantityKind kind = find_known_input(name)->kind;
    const bool has_value = table.has_column(name), has_sd = table.has_column(name + "_sd");
    const bool has_min = table.has_column(name + "_min"), has_max = table.has_column(name + "_max");
    if (has_min != has_max) {
      throw Error(path + ": column '" + name + (has_min ? "_min" : "_max") + "' needs its partner '" + name +
                  (has_min ? "_max" : "_min") + "' (a uniform range)");
    }
    if (has_sd && has_min) throw Error(path + ": " + name + " has both an SD and a range: give one of them");
    if (!has_value && !has_min) throw Error(path + ": column '" + name + "_sd' needs the value column '" + name + "'");
    std::vector<double> value, lo, hi, sd;
    if (has_value) value = table.si_column(name, kind);
    if (has_min) {
      lo = table.si_column(name + "_min", kind);
      hi = table.si_column(name + "_max", kind);
    }
    // An SD is a difference: a temperature SD in °C is the same number of kelvin.
    if (has_sd) {
      sd = table.si_column(name + "_sd", kind);
      if (kind == QuantityKind::temperature) {
        const double offset = unit_to_si(table.columns[table.column(name + "_sd")].unit).offset;
        for (double& x : sd) x -= offset;
      }
    }
    for (size_t i = 0; i < static_cast<size_t>(n); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      if (has_min) {
        if (!(lo[i] <= hi[i])) throw Error(where(i, name + "_min") + ": the minimum is above the maximum");
        const double middle = 0.5 * (lo[i] + hi[i]);
        if (has_value && (value[i] < lo[i] || value[i] > hi[i])) {
          throw Error(where(i, name) + ": the value lies outside its range " + name + "_min .. " + name + "_max");
        }
        data.conditions(r, j) = has_value ? value[i] : middle;
        data.condition_half_width(r, j) = 0.5 * (hi[i] - lo[i]);
        if (has_value && value[i] != middle) {
          // A uniform range is centred on its middle: the stated value is the range's.
          data.conditions(r, j) = middle;
        }
      } else {
        data.conditions(r, j) = value[i];
      }
      if (has_sd) {
        if (!(std::isfinite(sd[i]) && sd[i] >= 0.0)) throw Error(where(i, name + "_sd") + ": an SD must be zero or positive");
        data.condition_sd(r, j) = sd[i];
      }
      for (const double x : {data.conditions(r, j) - data.condition_half_width(r, j), data.conditions(r, j) + data.condition_half_width(r, j)}) {
        const std::string why = physical_range_violation(x, kind);
        if (!why.empty()) throw Error(where(i, name) + ": " + why);
      }
    }
  }
  const std::vector<double> mu = table.si_column("mu", QuantityKind::dimensionless);
  const std::vector<double> sd = table.si_column("mu_sd", QuantityKind::dimensionless);
  data.mu = Eigen::Map<const Eigen::VectorXd>(mu.data(), n);
  data.mu_sd = Eigen::Map<const Eigen::VectorXd>(sd.data(), n);
  for (Eigen::Index i = 0; i < n; ++i) {
    data.row_names.push_back(std::filesystem::path(path).filename().string() + " line " +
                             std::to_string(table.line_of_row[static_cast<size_t>(i)]));
  }
  data.data_sets = {std::filesystem::path(path).stem().string()};
  data.data_set_of_row.assign(static_cast<size_t>(n), 0);
  return data;
}

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
    if (!input.contains(coordinates(j))) return kMinusInfinity;
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
      return kMinusInfinity;  // the emulator knows nothing there: the prior is cut to the box
    }
    log_density += latent_priors_[static_cast<size_t>(l)].log_density(value);
  }
  if (!std::isfinite(log_density)) return kMinusInfinity;

  const Likelihood likelihood = likelihood_at(point_at(natural));
  if (likelihood.factor.info() != Eigen::Success) return kMinusInfinity;
  const Eigen::VectorXd whitened = likelihood.factor.matrixL().solve(likelihood.residual);
  const double log_determinant_half = likelihood.factor.matrixLLT().diagonal().array().log().sum();
  const double value = log_density - 0.5 * whitened.squaredNorm() - log_determinant_half;
  return std::isfinite(value) ? value : kMinusInfinity;
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

CalibrationResult calibrate(const CalibrationProblem& problem, const EnsembleOptions& options, const SamplerProgress& progress) {
  const LogDensity log_posterior = [&problem](const Eigen::VectorXd& c) { return problem.log_posterior(c); };
  EnsembleChains chains = run_ensemble_sampler(log_posterior, problem.draw_start(options.walkers, options.seed), options, progress);
  CalibrationResult result;
  result.options = options;
  result.diagnostics = diagnose_chains(chains);
  result.convergence_failure = convergence_failure(result.diagnostics, problem.coordinate_names(), chains.steps());
  // Not yet within the limits: run on from where the walkers are for as many steps as were run in all,
  // and judge that latest run alone (the earlier steps become its burn-in: "run longer and discard the
  // first half", BDA3 §11.4), while the whole stays within max_steps.
  long long total = options.burn_in_steps + options.steps;
  for (std::uint64_t stage = 1; !result.convergence_failure.empty() && 2 * total <= options.max_steps; ++stage) {
    Eigen::MatrixXd last(options.walkers, problem.dimension());
    for (int w = 0; w < options.walkers; ++w) last.row(w) = chains.states[static_cast<size_t>(w)].bottomRows(1);
    EnsembleOptions more = options;
    more.burn_in_steps = 0;
    more.steps = static_cast<int>(total);
    more.seed = options.seed + stage;
    chains = run_ensemble_sampler(log_posterior, last, more, progress);
    result.options.burn_in_steps = static_cast<int>(total);
    result.options.steps = static_cast<int>(total);
    total *= 2;
    result.diagnostics = diagnose_chains(chains);
    result.convergence_failure = convergence_failure(result.diagnostics, problem.coordinate_names(), chains.steps());
  }
  result.acceptance = chains.acceptance;
  result.samples = chains.pooled();
  if (problem.discrepancy()) {
    result.samples.middleCols(problem.discrepancy_offset(), 2) = result.samples.middleCols(problem.discrepancy_offset(), 2).array().exp().matrix();
  }
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
  kept_.resize(used, samples.cols());
  for (Eigen::Index s = 0; s < used; ++s) {
    // Evenly spaced through the pooled samples (walker by walker), so every walker contributes.
    kept_.row(s) = samples.row(s * total / used);
    Sample sample;
    sample.point = problem_->point_at(kept_.row(s).transpose());
    sample.likelihood = problem_->likelihood_at(sample.point);
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
  Eigen::MatrixXd block(kPredictionBlockRows, conditions.cols());
  // The samples' threads are the parallelism: each block's whitening runs on its own thread.
  const SingleThreadedBlas one_blas_thread;
  for (Eigen::Index first = 0; first < q; first += kPredictionBlockRows) {
    const Eigen::Index count = std::min(kPredictionBlockRows, q - first);
    block.topRows(count) = conditions.middleRows(first, count);
    for (Eigen::Index r = count; r < kPredictionBlockRows; ++r) block.row(r) = conditions.row(first + count - 1);
    predict_block(block, count, first, max_threads, out);
  }
  return out;
}

void CalibratedPosterior::predict_block(const Eigen::MatrixXd& conditions, Eigen::Index count, Eigen::Index first,
                                        int max_threads, CalibratedPrediction& out) const {
  const CalibrationProblem& problem = *problem_;
  const GaussianProcess& emulator = problem.emulator();
  const Eigen::Index q = conditions.rows(), used = static_cast<Eigen::Index>(samples_.size());
  if (q != kPredictionBlockRows) throw Error("calibrated prediction: a block of " + std::to_string(q) + " rows");
  const Eigen::MatrixXd unit_new = problem.discrepancy() ? problem.unit_conditions(conditions) : Eigen::MatrixXd();
  Eigen::MatrixXd means(q, used), variances(q, used), discrepancy_means(q, used), discrepancy_variances(q, used),
      emulator_variances(q, used);
  const double trend_sd = problem.priors().discrepancy_trend_sd;
  auto predict_sample = [&](Eigen::Index s, const GaussianProcess::LatentPoints& at) {
    const Sample& sample = samples_[static_cast<size_t>(s)];
    const auto lower = sample.likelihood.factor.matrixL();
    // ζ(x) = η(x, θ) + δ(x) given y (KOH eq. 6): cov(η(x), y) = C_η(x, X), cov(δ(x), y) = K_δ(x, X).
    // diag(A C⁻¹ Aᵀ) = |L⁻¹Aᵀ|² per column, with C = LLᵀ the likelihood's factor.
    const Eigen::MatrixXd emulator_cross = emulator.latent_covariance(at, sample.likelihood.measured);
    const Eigen::MatrixXd emulator_explained = lower.solve(emulator_cross.transpose());
    const Eigen::VectorXd prior_emulator_variance = emulator.latent_variance(at);
    emulator_variances.col(s) = prior_emulator_variance - emulator_explained.colwise().squaredNorm().transpose();
    if (problem.discrepancy()) {
      const Eigen::MatrixXd discrepancy_cross =
          CalibrationProblem::discrepancy_covariance(unit_new, sample.likelihood.unit_conditions, sample.point.amplitude,
                                                     sample.point.length_scale, trend_sd);
      const Eigen::VectorXd discrepancy_variance =
          CalibrationProblem::discrepancy_variance(unit_new, sample.point.amplitude, trend_sd);
      const Eigen::MatrixXd discrepancy_explained = lower.solve(discrepancy_cross.transpose());
      discrepancy_means.col(s) = discrepancy_cross * sample.weights;
      discrepancy_variances.col(s) =
          discrepancy_variance - discrepancy_explained.colwise().squaredNorm().transpose();
      means.col(s) = at.mean + emulator_cross * sample.weights + discrepancy_means.col(s);
      variances.col(s) = prior_emulator_variance.array() + discrepancy_variance.array() -
                         (emulator_explained + discrepancy_explained).colwise().squaredNorm().transpose().array();
    } else {
      discrepancy_means.col(s).setZero();
      discrepancy_variances.col(s).setZero();
      means.col(s) = at.mean + emulator_cross * sample.weights;
      variances.col(s) = emulator_variances.col(s);
    }
  };
  // The emulator's points of kSamplesPerWhitening samples are whitened together, one full block of
  // the GP's batch product (2.6× Eigen's SSE2 product in a portable build; bench/RESULTS.md); the
  // last group is padded with copies of the last sample, so every block has the same shape and a
  // sample's bits do not depend on how many were kept. Each sample writes its own columns: the
  // threads share nothing but what they read.
  static_assert(kGpQueryBlock % kPredictionBlockRows == 0);
  constexpr Eigen::Index kSamplesPerWhitening = kGpQueryBlock / kPredictionBlockRows;
  const Eigen::Index groups = (used + kSamplesPerWhitening - 1) / kSamplesPerWhitening;
  auto predict_group = [&](Eigen::Index group) {
    Eigen::MatrixXd stacked;
    for (Eigen::Index j = 0; j < kSamplesPerWhitening; ++j) {
      const Eigen::Index s = std::min(group * kSamplesPerWhitening + j, used - 1);
      const Eigen::MatrixXd points = problem.emulator_points(conditions, samples_[static_cast<size_t>(s)].point.theta);
      if (j == 0) stacked.resize(kGpQueryBlock, points.cols());
      stacked.middleRows(j * q, q) = points;
    }
    const GaussianProcess::LatentPoints all = emulator.latent_points(stacked);
    for (Eigen::Index j = 0; j < kSamplesPerWhitening && group * kSamplesPerWhitening + j < used; ++j) {
      predict_sample(group * kSamplesPerWhitening + j, all.rows(j * q, q));
    }
  };
  const int team = evaluation_team_size(max_threads);
#pragma omp parallel for num_threads(team) schedule(static) if (team > 1)
  for (Eigen::Index group = 0; group < groups; ++group) predict_group(group);

  // A mixture's moments: the mean of the means; the mean variance plus the variance of the means.
  auto spread = [used](const Eigen::MatrixXd& m) {
    const Eigen::VectorXd centre = m.rowwise().mean();
    return Eigen::VectorXd(((m.colwise() - centre).array().square().rowwise().sum() / static_cast<double>(used)).matrix());
  };
  const Eigen::VectorXd between = spread(means);
  const Eigen::VectorXd within = variances.rowwise().mean().cwiseMax(0.0);
  out.mean.segment(first, count) = means.rowwise().mean().head(count);
  out.parameter_sd.segment(first, count) = between.cwiseSqrt().head(count);
  out.sd.segment(first, count) = (within + between).cwiseSqrt().head(count);
  out.conditional_sd.segment(first, count) = within.cwiseSqrt().head(count);
  out.emulator_sd.segment(first, count) = emulator_variances.rowwise().mean().cwiseMax(0.0).cwiseSqrt().head(count);
  out.discrepancy_mean.segment(first, count) = discrepancy_means.rowwise().mean().head(count);
  out.discrepancy_sd.segment(first, count) =
      (discrepancy_variances.rowwise().mean().cwiseMax(0.0) + spread(discrepancy_means)).cwiseSqrt().head(count);
}

CalibratedPrediction predict_calibrated(const CalibrationProblem& problem, const CalibrationResult& result,
                                        const Eigen::MatrixXd& conditions, Eigen::Index thinned) {
  // Not owned: the posterior lives only for this call.
  const std::shared_ptr<const CalibrationProblem> borrowed(&problem, [](const CalibrationProblem*) {});
  return CalibratedPosterior(borrowed, result.samples, thinned).predict(conditions);
}

}  // namespace mufric
