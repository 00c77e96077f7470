#include "surrogate/calibration/measurements.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/units.hpp"

namespace mufric {

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

InputSpace box_for_measurements(const Measurements& data, double margin) {
  if (!(margin >= 0.0)) throw Error("the box's margin must be 0 or more (a share of each condition's width)");
  const Measurements full = completed(data);
  InputSpace box;
  for (Eigen::Index c = 0; c < static_cast<Eigen::Index>(full.condition_names.size()); ++c) {
    const std::string& name = full.condition_names[static_cast<size_t>(c)];
    const QuantityKind kind = kind_of_input(name);
    const bool logarithmic = kind == QuantityKind::pressure || kind == QuantityKind::velocity;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (Eigen::Index i = 0; i < full.rows(); ++i) {
      const double spread = std::max(kBoxSds * full.condition_sd(i, c), full.condition_half_width(i, c));
      double low = full.conditions(i, c) - spread, high = full.conditions(i, c) + spread;
      // A log box cannot reach 0: an SD as large as the value keeps the value's own decade below it.
      if (logarithmic && !(low > 0.0)) low = full.conditions(i, c) / 10.0;
      lo = std::min(lo, low);
      hi = std::max(hi, high);
    }
    if (logarithmic) {
      if (!(lo > 0.0)) throw Error("measurements: " + name + " must be positive to set a campaign's box");
      const double widen = margin * std::log(hi / lo);
      lo *= std::exp(-widen), hi *= std::exp(widen);
      if (widen == 0.0) lo /= 1.1, hi *= 1.1;  // one value: a box around it
    } else {
      const double widen = margin * (hi - lo);
      lo -= widen, hi += widen;
      if (widen == 0.0) lo -= 0.1 * std::abs(lo), hi += 0.1 * std::abs(hi);
      if (kind == QuantityKind::temperature) lo = std::max(lo, kLowestBoxTemperature);
    }
    box.push_back({name, std::string(si_unit(kind)), lo, hi});
  }
  return box;
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
      sd = table.si_difference_column(name + "_sd", kind);
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

}  // namespace mufric
