#pragma once
// The command-line flag that gives each model input its value (predict) or range (dataset plan).
#include <string_view>
#include <vector>

#include "common/registry.hpp"
#include "common/units.hpp"

namespace mufric::app {

struct InputFlag {
  std::string_view name;  // the input (common/units.hpp input_name)
  std::string_view flag;
};

inline const std::vector<InputFlag>& input_flags() {
  static const std::vector<InputFlag> flags{{input_name::contact_pressure, "--p"},
                                            {input_name::sliding_velocity, "--v"},
                                            {input_name::temperature, "--T"},
                                            {input_name::fibre_angle, "--angle"},
                                            {input_name::adhesive_coefficient, "--adhesive-coefficient"},
                                            {input_name::shear_factor, "--shear-factor"},
                                            {input_name::childs_exponent, "--childs-exponent"}};
  return flags;
}

// The input's flag; "" for an input without one.
inline std::string_view flag_of(std::string_view input) {
  const InputFlag* found = find_entry(input_flags(), input);
  return found == nullptr ? std::string_view() : found->flag;
}

}  // namespace mufric::app
