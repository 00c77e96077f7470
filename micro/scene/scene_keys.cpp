#include "micro/scene/scene_keys.hpp"

#include <map>
#include <sstream>
#include <vector>

#include "micro/contact/interface_law.hpp"
#include "micro/scene/scene.hpp"

namespace mufric::scene {
namespace {

// The readings whose union is every key a scene can set: the default dry scene reads the dry
// sections, lubricated adds lubricant.*, seed 000's protocol its time.* keys.
const std::vector<std::vector<std::string>>& kReadings() {
  static const std::vector<std::vector<std::string>> readings = {
      {}, {"physics=lubricated"}, {"protocol.name=seed-000"}, {"physics=lubricated", "protocol.name=seed-000"}};
  return readings;
}

std::string section_of(const std::string& path) { return path.substr(0, path.find('.')); }

// The laws that declare a contact key ("shear_factor" or "wetted.shear_factor").
std::string laws_reading(const std::string& path) {
  std::string laws;
  for (const auto& law : contact::interface_laws()) {
    for (const auto key : law.keys) {
      if ("contact." + std::string(key) == path) laws += (laws.empty() ? "" : ", ") + std::string(law.name);
    }
  }
  return laws;
}

}  // namespace

std::string scene_key_reference() {
  std::map<std::string, OptionKeyRead> keys;
  for (const auto& overrides : kReadings()) {
    const Scene s = scene_with_overrides(default_scene_json(), overrides, "default scene");
    for (const auto& [path, read] : s.keys_read) keys.emplace(path, read);
  }
  // The laws' keys the default law does not read: named with the laws that read them.
  for (const auto& law : contact::interface_laws()) {
    for (const auto key : law.keys) keys.emplace("contact." + std::string(key), OptionKeyRead{"law key", "", ""});
  }
  std::ostringstream out;
  std::string section;
  for (const auto& [path, read] : keys) {
    if (section_of(path) != section) {
      section = section_of(path);
      out << "### " << section << "\n\n";
    }
    out << "#### `" << path << "`\n" << read.type;
    if (!read.if_absent.empty()) out << "; if absent: " << read.if_absent;
    if (!read.allowed.empty()) out << "; " << read.allowed;
    const std::string laws = laws_reading(path);
    if (!laws.empty()) out << "; read when contact.law is " << laws;
    out << "\n";
    if (path == "contact.law") {
      out << "\n| law | what it is | its keys |\n|---|---|---|\n";
      for (const auto& law : contact::interface_laws()) {
        std::string law_keys;
        for (const auto key : law.keys) law_keys += (law_keys.empty() ? "" : ", ") + ("`contact." + std::string(key) + "`");
        out << "| " << law.name << " | " << law.summary << " | " << law_keys << " |\n";
      }
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace mufric::scene
