#pragma once
// Named, ordered model inputs with SI units and the box they were sampled from.
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "common/units.hpp"

namespace mufric {

struct InputSpec {
  std::string name;  // contact_pressure, sliding_velocity, temperature, fibre_angle, ...
  std::string unit;  // SI symbol: Pa, m/s, K, rad
  double lo = 0.0;   // training box, SI
  double hi = 0.0;

  QuantityKind kind() const { return kind_of_input(name); }
  // An angle repeats every 180° (a ply at θ and θ + 180° is the same ply): 270° lies in a box of
  // 0°–90°. Other inputs: the closed interval [lo, hi].
  // Quiet comparisons: a NaN is outside without raising FE_INVALID in a caller that traps it.
  bool contains(double value) const {
    if (std::isgreaterequal(value, lo) && std::islessequal(value, hi)) return true;
    if (kind() != QuantityKind::angle || !std::isfinite(value)) return false;
    constexpr double kHalfTurn = 3.14159265358979323846;
    const double wrapped = lo + (value - lo) - kHalfTurn * std::floor((value - lo) / kHalfTurn);
    return wrapped >= lo && wrapped <= hi;
  }
};

using InputSpace = std::vector<InputSpec>;

// The inputs' names, in their order.
inline std::vector<std::string> input_names(const InputSpace& inputs) {
  std::vector<std::string> names;
  for (const InputSpec& input : inputs) names.push_back(input.name);
  return names;
}

// The same inputs in the same order, with the same units and boxes.
inline bool same_input_space(const InputSpace& a, const InputSpace& b) {
  if (a.size() != b.size()) return false;
  for (size_t j = 0; j < a.size(); ++j) {
    if (a[j].name != b[j].name || a[j].unit != b[j].unit || a[j].lo != b[j].lo || a[j].hi != b[j].hi) return false;
  }
  return true;
}

// Where two input spaces differ, for a message that says what to fix: the first input whose name,
// unit or box differs, both versions side by side and each named by where it came from ("input 3
// differs: temperature [K] 298.15..1073.15 (25°C..800°C) in b.h5, temperature [K] 298.15..1173.15
// (25°C..900°C) in a.h5"), or the two lists of names when the counts differ. Empty when they are the same.
std::string input_space_difference(const InputSpace& a, std::string_view a_source, const InputSpace& b,
                                   std::string_view b_source);

// The default parameter box of seed 000 section 4: p 300–1300 MPa, v 22.5–200 m/min, T 25–900 °C.
inline InputSpace default_friction_box() {
  return {{std::string(input_name::contact_pressure), "Pa", 300e6, 1300e6},
          {std::string(input_name::sliding_velocity), "m/s", 22.5 / 60.0, 200.0 / 60.0},
          {std::string(input_name::temperature), "K", 25.0 + 273.15, 900.0 + 273.15}};
}

}  // namespace mufric

namespace mufric {
namespace h5 {
class Reader;
class Writer;
}  // namespace h5

// <group>/{names, units, box_lo, box_hi} — shared by dataset and model files (a calibrated model also
// keeps its campaign emulator's inputs in a group of its own).
void write_input_space(h5::Writer& out, const InputSpace& inputs, const std::string& group = "/inputs");
// Validates: equal lengths, at least one input, finite boxes with lo < hi, SI units for known names.
InputSpace read_input_space(const h5::Reader& in, const std::string& group = "/inputs");
}  // namespace mufric
