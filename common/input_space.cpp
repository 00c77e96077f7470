#include "common/input_space.hpp"

#include <cmath>

#include "common/h5_file.hpp"

namespace mufric {

void write_input_space(h5::Writer& out, const InputSpace& inputs) {
  std::vector<std::string> names, units;
  std::vector<double> lo, hi;
  for (const auto& input : inputs) {
    names.push_back(input.name);
    units.push_back(input.unit);
    lo.push_back(input.lo);
    hi.push_back(input.hi);
  }
  out.group("/inputs");
  out.strings("/inputs/names", names);
  out.strings("/inputs/units", units);
  out.doubles("/inputs/box_lo", lo);
  out.doubles("/inputs/box_hi", hi);
}

InputSpace read_input_space(const h5::Reader& in) {
  const auto names = in.strings("/inputs/names");
  const auto units = in.strings("/inputs/units");
  const auto lo = in.doubles("/inputs/box_lo");
  const auto hi = in.doubles("/inputs/box_hi");
  if (names.empty()) in.fail("/inputs/names", "no inputs declared");
  if (units.size() != names.size() || lo.size() != names.size() || hi.size() != names.size()) {
    in.fail("/inputs", "names, units, box_lo and box_hi differ in length");
  }
  InputSpace space;
  for (size_t i = 0; i < names.size(); ++i) {
    if (!(lo[i] < hi[i]) || !std::isfinite(lo[i]) || !std::isfinite(hi[i])) {
      in.fail("/inputs/box_lo", "input '" + names[i] + "' has an empty or non-finite box");
    }
    const QuantityKind kind = kind_of_input(names[i]);
    if (kind != QuantityKind::dimensionless && units[i] != si_unit(kind)) {
      in.fail("/inputs/units", "input '" + names[i] + "' is stored in '" + units[i] + "', expected SI '" +
                                   std::string(si_unit(kind)) + "'");
    }
    space.push_back({names[i], units[i], lo[i], hi[i]});
  }
  return space;
}

}  // namespace mufric
