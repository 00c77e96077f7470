#include "common/input_space.hpp"

#include <cmath>
#include <cstdio>

#include "common/h5_file.hpp"
#include "common/wording.hpp"

namespace mufric {

void write_input_space(h5::Writer& out, const InputSpace& inputs, const std::string& group) {
  std::vector<std::string> names, units;
  std::vector<double> lo, hi;
  for (const auto& input : inputs) {
    names.push_back(input.name);
    units.push_back(input.unit);
    lo.push_back(input.lo);
    hi.push_back(input.hi);
  }
  out.group(group);
  out.strings(group + "/names", names);
  out.strings(group + "/units", units);
  out.doubles(group + "/box_lo", lo);
  out.doubles(group + "/box_hi", hi);
}

namespace {

// "temperature [K] 298.15..1173.15 (25°C..900°C)": the stored unit and SI box, digits enough to show a
// difference in the last place, and the box in the units a user typed when the input is a known one.
std::string input_text(const InputSpec& input) {
  char box[64];
  std::snprintf(box, sizeof box, "%.10g..%.10g", input.lo, input.hi);
  std::string text = input.name + " [" + input.unit + "] " + box;
  const QuantityKind kind = input.kind();
  if (kind != QuantityKind::dimensionless) {
    text += " (" + format_human(input.lo, kind) + ".." + format_human(input.hi, kind) + ")";
  }
  return text;
}

std::string names_of(const InputSpace& inputs) {
  std::string names;
  for (const auto& input : inputs) names += (names.empty() ? "" : ", ") + input.name;
  return names;
}

}  // namespace

std::string input_space_difference(const InputSpace& a, std::string_view a_source, const InputSpace& b,
                                   std::string_view b_source) {
  if (a.size() != b.size()) {
    return std::string(a_source) + " has " + count_of(static_cast<long long>(a.size()), "input", "inputs") + " (" +
           names_of(a) + "), " + std::string(b_source) + " has " + std::to_string(b.size()) + " (" + names_of(b) + ")";
  }
  for (size_t j = 0; j < a.size(); ++j) {
    if (same_input_space({a[j]}, {b[j]})) continue;
    return "input " + std::to_string(j + 1) + " differs: " + input_text(a[j]) + " in " + std::string(a_source) + ", " +
           input_text(b[j]) + " in " + std::string(b_source);
  }
  return "";
}

InputSpace read_input_space(const h5::Reader& in, const std::string& group) {
  const auto names = in.strings(group + "/names");
  const auto units = in.strings(group + "/units");
  const auto lo = in.doubles(group + "/box_lo");
  const auto hi = in.doubles(group + "/box_hi");
  if (names.empty()) in.fail(group + "/names", "no inputs declared");
  if (units.size() != names.size() || lo.size() != names.size() || hi.size() != names.size()) {
    in.fail(group, "names, units, box_lo and box_hi differ in length");
  }
  InputSpace space;
  for (size_t i = 0; i < names.size(); ++i) {
    if (!(lo[i] < hi[i]) || !std::isfinite(lo[i]) || !std::isfinite(hi[i])) {
      in.fail(group + "/box_lo", "input '" + names[i] + "' has an empty or non-finite box");
    }
    const QuantityKind kind = kind_of_input(names[i]);
    if (kind != QuantityKind::dimensionless && units[i] != si_unit(kind)) {
      in.fail(group + "/units", "input '" + names[i] + "' is stored in '" + units[i] + "', expected SI '" +
                                   std::string(si_unit(kind)) + "'");
    }
    space.push_back({names[i], units[i], lo[i], hi[i]});
  }
  return space;
}

}  // namespace mufric
