#pragma once
// The contact module's options as a scene states them (the `contact` section), with their defaults
// and reader: the penalty, the interface law (read by its registry entry, which names the keys it
// reads; another law's key is recorded as read without effect), stick's tangential penalty and the
// heat partition. The scene only composes these; a contact option is added here and nowhere else.
#include <string>
#include <string_view>
#include <vector>

#include "micro/contact/interface_laws.hpp"
#include "micro/contact/mortar_contact.hpp"
#include "micro/settings/option_keys.hpp"

namespace mufric::contact {

struct ContactOptions {
  double penalty = kDefaultPenalty;  // Pa/m (seed 000)
  // The interface law (frictionless unless contact.law says otherwise), stick's penalty, the heat partition.
  ContactInterface interface{.law = std::make_shared<FrictionlessLaw>()};
  // Reads the section; a law's file key (the table law's) resolves against `base_directory`.
  static ContactOptions read(OptionKeys& keys, const std::string& base_directory);
  bool operator==(const ContactOptions&) const = default;
};

// The law coefficients a campaign may vary as model inputs (common/units.hpp input_name), each by the
// key that sets it in the contact section.
struct CoefficientInput {
  std::string_view input;
  std::string_view key;
};
const std::vector<CoefficientInput>& coefficient_inputs();

}  // namespace mufric::contact
