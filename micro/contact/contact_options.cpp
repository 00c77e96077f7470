#include "micro/contact/contact_options.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace mufric::contact {
namespace {

// Where a law's key lives: "x" in the contact section, "wetted.x" as x in its wetted subsection.
std::pair<OptionKeys&, std::string> law_key_section(std::string_view key, OptionKeys& contact, OptionKeys& wetted) {
  constexpr std::string_view kWettedPrefix = "wetted.";
  if (key.starts_with(kWettedPrefix)) return {wetted, std::string(key.substr(kWettedPrefix.size()))};
  return {contact, std::string(key)};
}

// The law's coefficient keys as a file spells them (contact.*, contact.wetted.*), with the file, the
// key and the law named in every error. A law reads only the keys its registry entry declares (a
// logic error otherwise: the record of another law's keys rests on those lists).
class FileLawKeys final : public LawKeys {
 public:
  FileLawKeys(OptionKeys& contact, OptionKeys& wetted, const InterfaceLawEntry& law, const std::string& base_directory)
      : contact_(contact), wetted_(wetted), law_(law), base_directory_(base_directory) {}
  double required_number(std::string_view key, double lo, double hi, std::string_view example) override {
    auto [section, name] = locate(key);
    require(section, name, example);
    return section.number(name, 0.0, lo, hi);
  }
  double number(std::string_view key, double fallback, double lo, double hi) override {
    auto [section, name] = locate(key);
    return section.number(name, fallback, lo, hi);
  }
  std::string required_file(std::string_view key, std::string_view example) override {
    auto [section, name] = locate(key);
    require(section, name, example);
    std::string path = section.text(name, "", {});
    if (std::filesystem::path(path).is_relative()) path = (std::filesystem::path(base_directory_) / path).string();
    if (!std::filesystem::exists(path)) section.fail(name, "no such file '" + path + "'");
    return path;
  }
  [[noreturn]] void fail(std::string_view key, const std::string& message) override {
    auto [section, name] = locate(key);
    section.fail(name, message);
  }

 private:
  std::pair<OptionKeys&, std::string> locate(std::string_view key) {
    if (std::find(law_.keys.begin(), law_.keys.end(), key) == law_.keys.end()) {
      throw std::logic_error("contact law " + std::string(law_.name) + " reads contact." + std::string(key) +
                             ", which its registry entry does not declare");
    }
    return law_key_section(key, contact_, wetted_);
  }
  void require(const OptionKeys& section, const std::string& name, std::string_view example) const {
    if (!section.has(name)) {
      section.fail(name, "required when contact.law is " + std::string(law_.name) + " (" + std::string(example) + ")");
    }
  }
  OptionKeys& contact_;
  OptionKeys& wetted_;
  const InterfaceLawEntry& law_;
  const std::string& base_directory_;
};

// Another law's key that this one leaves unread is recorded as read without effect, not an error:
// switching laws with --set keeps a scene's other coefficients.
void record_other_laws_keys(OptionKeys& contact, OptionKeys& wetted, const InterfaceLawEntry& law) {
  for (const auto& other : interface_laws()) {
    for (const std::string_view key : other.keys) {
      if (std::find(law.keys.begin(), law.keys.end(), key) != law.keys.end()) continue;
      auto [section, name] = law_key_section(key, contact, wetted);
      section.ineffective(name, "contact.law is " + std::string(law.name));
    }
  }
}

}  // namespace

ContactOptions ContactOptions::read(OptionKeys& c, const std::string& base_directory) {
  ContactOptions o;
  o.penalty = c.number("penalty", o.penalty, 1e3, 1e30);
  // The interfacial law: frictionless is seed 000's model (μ from ploughing alone) and the default.
  std::vector<std::string> names;
  for (const auto& law : interface_laws()) names.emplace_back(law.name);
  const std::string law_name = c.text("law", names.front(), names);
  const InterfaceLawEntry& entry = *find_interface_law(law_name);
  OptionKeys wetted = c.child("wetted");
  FileLawKeys keys(c, wetted, entry, base_directory);
  o.interface.law = entry.read(keys);
  record_other_laws_keys(c, wetted, entry);
  wetted.finish();
  // Stick's regularisation; absent, 0: the contact's default, a tenth of the normal penalty
  // (kTangentialPenaltyRatio, applied in one place, MortarContact). The heat partition: the share of
  // the frictional heat that enters the chip (kDefaultHeatPartition says why 0.5).
  if (o.interface.law->frictional()) {
    o.interface.tangential_penalty = c.number("tangential_penalty", 0.0, 1e3, 1e30);
    o.interface.heat_partition = c.number("heat_partition", kDefaultHeatPartition, kHeatPartitionRange.lo, kHeatPartitionRange.hi);
  } else {
    for (const char* key : {"tangential_penalty", "heat_partition"}) c.ineffective(key, "contact.law is " + law_name);
  }
  return o;
}

const std::vector<CoefficientInput>& coefficient_inputs() {
  static const std::vector<CoefficientInput> inputs{{input_name::adhesive_coefficient, "adhesive_coefficient"},
                                                    {input_name::shear_factor, "shear_factor"},
                                                    {input_name::childs_exponent, "childs_exponent"}};
  return inputs;
}

}  // namespace mufric::contact
