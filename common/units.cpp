#include "common/units.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "common/registry.hpp"

#include "common/error.hpp"
#include "common/wording.hpp"

namespace mufric {
namespace {

constexpr double kZeroCelsiusInKelvin = 273.15;
constexpr double kPi = 3.14159265358979323846;

struct UnitEntry {
  std::string_view symbol;
  UnitToSi to_si;
};

constexpr std::array kUnits{
    UnitEntry{"Pa", {QuantityKind::pressure, 1.0, 0.0}},
    UnitEntry{"kPa", {QuantityKind::pressure, 1e3, 0.0}},
    UnitEntry{"MPa", {QuantityKind::pressure, 1e6, 0.0}},
    UnitEntry{"GPa", {QuantityKind::pressure, 1e9, 0.0}},
    UnitEntry{"N/mm2", {QuantityKind::pressure, 1e6, 0.0}},
    UnitEntry{"m/s", {QuantityKind::velocity, 1.0, 0.0}},
    UnitEntry{"m/min", {QuantityKind::velocity, 1.0 / 60.0, 0.0}},
    UnitEntry{"mm/s", {QuantityKind::velocity, 1e-3, 0.0}},
    UnitEntry{"mm/min", {QuantityKind::velocity, 1e-3 / 60.0, 0.0}},
    UnitEntry{"K", {QuantityKind::temperature, 1.0, 0.0}},
    UnitEntry{"C", {QuantityKind::temperature, 1.0, kZeroCelsiusInKelvin}},
    UnitEntry{"degC", {QuantityKind::temperature, 1.0, kZeroCelsiusInKelvin}},
    UnitEntry{"°C", {QuantityKind::temperature, 1.0, kZeroCelsiusInKelvin}},
    UnitEntry{"rad", {QuantityKind::angle, 1.0, 0.0}},
    UnitEntry{"deg", {QuantityKind::angle, kPi / 180.0, 0.0}},
    UnitEntry{"°", {QuantityKind::angle, kPi / 180.0, 0.0}},
    UnitEntry{"m", {QuantityKind::length, 1.0, 0.0}},
    UnitEntry{"mm", {QuantityKind::length, 1e-3, 0.0}},
    UnitEntry{"um", {QuantityKind::length, 1e-6, 0.0}},
    UnitEntry{"µm", {QuantityKind::length, 1e-6, 0.0}},
    UnitEntry{"nm", {QuantityKind::length, 1e-9, 0.0}},
    UnitEntry{"s", {QuantityKind::time, 1.0, 0.0}},
    UnitEntry{"ms", {QuantityKind::time, 1e-3, 0.0}},
    UnitEntry{"us", {QuantityKind::time, 1e-6, 0.0}},
    UnitEntry{"ns", {QuantityKind::time, 1e-9, 0.0}},
    UnitEntry{"1", {QuantityKind::dimensionless, 1.0, 0.0}},
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Each kind's words: its name, its SI unit, the unit people write it in, an example of a value.
struct KindWords {
  QuantityKind kind;
  std::string_view name, si_unit, human_unit, example;
};
constexpr KindWords kKindWords[] = {
    {QuantityKind::pressure, "pressure", "Pa", "MPa", "800MPa"},
    {QuantityKind::velocity, "velocity", "m/s", "m/min", "100m/min"},
    {QuantityKind::temperature, "temperature", "K", "°C", "500C"},
    {QuantityKind::angle, "angle", "rad", "deg", "90deg"},
    {QuantityKind::length, "length", "m", "um", "10um"},
    {QuantityKind::time, "time", "s", "s", "2.5e-7s"},
    {QuantityKind::dimensionless, "dimensionless", "1", "", "0.3"},
};
constexpr KindWords kUnknownKind{QuantityKind::dimensionless, "unknown", "1", "", ""};

const KindWords& words_of(QuantityKind kind) {
  for (const KindWords& words : kKindWords) {
    if (words.kind == kind) return words;
  }
  return kUnknownKind;
}

}  // namespace

std::string_view to_string(QuantityKind kind) { return words_of(kind).name; }
std::string_view si_unit(QuantityKind kind) { return words_of(kind).si_unit; }
std::string_view human_unit(QuantityKind kind) { return words_of(kind).human_unit; }
std::string_view example_quantity(QuantityKind kind) { return words_of(kind).example; }

std::string lower_case(std::string_view text) {
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower;
}

// The known unit a typo most likely meant, compared without case ("mpa" is MPa): one of the wanted
// kind when a kind is wanted (a pressure's typo is never answered with a time), at most one edit per
// two characters typed and never more than two ("psi" is no typo of "Pa").
std::string_view nearest_unit(std::string_view unit, std::optional<QuantityKind> wanted) {
  constexpr size_t kMostEdits = 2;
  const size_t most_edits = std::min(kMostEdits, std::max<size_t>(1, unit.size() / 2));
  const std::string typed = lower_case(unit);
  std::vector<std::string> lowered;
  std::vector<std::string_view> symbols;
  for (const auto& entry : kUnits) {
    if (wanted && entry.to_si.kind != *wanted) continue;
    lowered.push_back(lower_case(entry.symbol));
    symbols.push_back(entry.symbol);
  }
  const std::vector<std::string_view> candidates(lowered.begin(), lowered.end());
  const std::string_view near = nearest_word(typed, candidates, most_edits);
  if (near.empty()) return {};
  return symbols[static_cast<size_t>(std::find(candidates.begin(), candidates.end(), near) - candidates.begin())];
}

UnitToSi unit_to_si(std::string_view unit, std::optional<QuantityKind> wanted) {
  unit = trim(unit);
  for (const auto& entry : kUnits) {
    if (entry.symbol == unit) return entry.to_si;
  }
  const std::string_view near = nearest_unit(unit, wanted);
  throw Error("unknown unit '" + std::string(unit) + "'" + (near.empty() ? "" : "; did you mean '" + std::string(near) + "'?") +
              " (known: Pa kPa MPa GPa, m/s m/min mm/s, K C degC, rad deg, m mm um nm, s ms us ns, 1)");
}

double parse_quantity(std::string_view text, QuantityKind expected, std::string_view field) {
  const std::string_view trimmed = trim(text);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(trimmed.data(), trimmed.data() + trimmed.size(), value);
  const std::string prefix = std::string(field) + ": '" + std::string(text) + "'";
  if (ec != std::errc() || !std::isfinite(value)) {
    throw Error(prefix + " is not a number with a unit (expected e.g. " +
                std::string(example_quantity(expected)) + ")");
  }
  const std::string_view unit = trim(std::string_view(end, trimmed.data() + trimmed.size() - end));
  if (unit.size() > 1 && unit.front() == ',' && std::isdigit(static_cast<unsigned char>(unit[1]))) {
    std::string with_point(trimmed);
    with_point[static_cast<size_t>(end - trimmed.data())] = '.';
    throw Error(prefix + " has a decimal comma; mufric reads a decimal point: '" + with_point + "'");
  }
  if (unit.empty() && expected != QuantityKind::dimensionless) {
    throw Error(prefix + " has no unit; " + with_article(to_string(expected)) +
                " needs one, e.g. " + std::string(example_quantity(expected)));
  }
  if (unit.empty()) return value;
  UnitToSi map{};
  try {
    map = unit_to_si(unit, expected);
  } catch (const Error& e) {
    throw Error(prefix + ": " + e.what());
  }
  if (map.kind != expected) {
    throw Error(prefix + " is " + with_article(to_string(map.kind)) + ", expected " +
                with_article(to_string(expected)) + " such as " +
                std::string(example_quantity(expected)));
  }
  return map.scale * value + map.offset;
}

double si_to_human(double value_si, QuantityKind kind) {
  switch (kind) {
    case QuantityKind::pressure: return value_si / 1e6;
    case QuantityKind::velocity: return value_si * 60.0;
    case QuantityKind::temperature: return value_si - kZeroCelsiusInKelvin;
    case QuantityKind::angle: return value_si * 180.0 / kPi;
    case QuantityKind::length: return value_si * 1e6;
    default: return value_si;
  }
}

std::string format_human_difference(double value_si, QuantityKind kind, int precision) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", precision, si_to_human(value_si, kind) - si_to_human(0.0, kind));
  return std::string(text) + (kind == QuantityKind::temperature ? " K" : std::string(human_unit(kind)));
}

std::string format_human(double value_si, QuantityKind kind, int precision) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", precision, si_to_human(value_si, kind));
  return std::string(text) + std::string(human_unit(kind));
}

const std::vector<KnownInput>& known_inputs() {
  static const std::vector<KnownInput> inputs{
      {input_name::contact_pressure, QuantityKind::pressure},
      {input_name::sliding_velocity, QuantityKind::velocity},
      {input_name::temperature, QuantityKind::temperature},
      {input_name::fibre_angle, QuantityKind::angle},  // the empirical FRP law's
      {input_name::adhesive_coefficient, QuantityKind::dimensionless, false},
      {input_name::shear_factor, QuantityKind::dimensionless, false},
      {input_name::childs_exponent, QuantityKind::dimensionless, false}};
  return inputs;
}

std::string servable_inputs_violation(const std::vector<std::string>& input_names) {
  for (const std::string& name : input_names) {
    const KnownInput* known = find_known_input(name);
    if (known == nullptr) return "its input '" + name + "' is not one mufric's wire and clients carry";
    if (!known->on_the_wire) {
      return "its input '" + name +
             "' is a coefficient of the interface law, which a served model must not leave open: calibrate it against "
             "measured friction and serve the calibrated model";
    }
  }
  return "";
}

const KnownInput* find_known_input(std::string_view input_name) { return find_entry(known_inputs(), input_name); }

const std::vector<std::string>& known_input_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const KnownInput& input : known_inputs()) n.emplace_back(input.name);
    return n;
  }();
  return names;
}

PhysicalRange physical_range(QuantityKind kind) {
  constexpr double kHighestPressure = 100e9;  // Pa
  constexpr double kHighestSpeed = 1000.0;     // m/s
  constexpr double kHighestTemperature = 1e4;  // K
  constexpr double inf = std::numeric_limits<double>::infinity();
  switch (kind) {
    case QuantityKind::pressure: return {0.0, kHighestPressure};
    case QuantityKind::velocity: return {0.0, kHighestSpeed};  // a speed: a direction is given apart
    case QuantityKind::temperature: return {0.0, kHighestTemperature};
    default: return {-inf, inf};
  }
}

std::string physical_range_violation(double value_si, QuantityKind kind) {
  if (!std::isfinite(value_si)) return "not a finite number";
  const PhysicalRange range = physical_range(kind);
  if (value_si >= range.lo && value_si <= range.hi) return "";
  const std::string value = format_human(value_si, kind);
  if (value_si < range.lo) {
    if (kind == QuantityKind::temperature) return value + " is below absolute zero (" + format_human(0.0, kind, 6) + ")";
    return value + " is below " + format_human(range.lo, kind) + ", the least " + with_article(to_string(kind)) + " can be";
  }
  return value + " is above " + format_human(range.hi, kind) + ", beyond any physical " + std::string(to_string(kind));
}

QuantityKind kind_of_input(std::string_view input_name) {
  const KnownInput* input = find_known_input(input_name);
  return input ? input->kind : QuantityKind::dimensionless;
}

}  // namespace mufric
