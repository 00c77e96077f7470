#include "surrogate/calibration/priors.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/error.hpp"
#include "common/units.hpp"
#include "surrogate/calibration/ensemble_sampler.hpp"  // uniform01

namespace mufric {
namespace {



// A standard normal from two uniforms (Box & Muller 1958), so that a seed gives the same draws on
// every standard library.
double standard_normal(std::mt19937_64& random) {
  const double u1 = 1.0 - uniform01(random());  // (0, 1]
  const double u2 = uniform01(random());
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}


}  // namespace

double draw_from(const Prior& prior, std::mt19937_64& random) {
  switch (prior.kind) {
    case PriorKind::uniform: return prior.a + (prior.b - prior.a) * uniform01(random());
    case PriorKind::normal: return prior.a + prior.b * standard_normal(random);
    case PriorKind::log_normal: return prior.a * std::exp(prior.b * standard_normal(random));
    case PriorKind::half_normal: return prior.a * std::abs(standard_normal(random));
  }
  return prior.a;
}


namespace {

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
  if (!std::isfinite(x)) return kLogZeroDensity;
  switch (kind) {
    case PriorKind::uniform: return x >= a && x <= b ? 0.0 : kLogZeroDensity;
    case PriorKind::normal: return -0.5 * ((x - a) / b) * ((x - a) / b);
    case PriorKind::log_normal: {
      if (x <= 0.0) return kLogZeroDensity;
      const double z = (std::log(x) - std::log(a)) / b;
      return -0.5 * z * z - std::log(x);
    }
    case PriorKind::half_normal: return x >= 0.0 ? -0.5 * (x / a) * (x / a) : kLogZeroDensity;
  }
  return kLogZeroDensity;
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
}  // namespace mufric
