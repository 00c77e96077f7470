#pragma once
// The priors of a calibration: one scalar's prior (its density, its draws, its mass in a range, its
// text) and the priors file (JSON) of the calibrated inputs, the discrepancy and the data sets' biases.
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/units.hpp"

namespace mufric {

// A prior on one scalar: uniform on [a, b]; normal of mean a and SD b; log-normal of median a and
// SD b of its log; half-normal of scale a (on x ≥ 0).
// The log density outside a prior's support (and of a posterior point the emulator cannot answer).
inline constexpr double kLogZeroDensity = -std::numeric_limits<double>::infinity();
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
// One draw from the prior (Box & Muller 1958 for the normal ones, so that a seed gives the same draws
// on every standard library).
double draw_from(const Prior& prior, std::mt19937_64& random);


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

}  // namespace mufric
