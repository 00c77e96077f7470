#pragma once
// Looking an entry up by name in one of mufric's registries (the interface laws, the model kinds):
// any vector of entries with a `name` field.
#include <string>
#include <string_view>
#include <vector>

namespace mufric {

// The entry called `name`; none when there is no such entry.
template <class Entry>
const Entry* find_entry(const std::vector<Entry>& entries, std::string_view name) {
  for (const Entry& entry : entries) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

// The entries' names, comma-separated, for messages and --help.
template <class Entry>
std::string entry_names(const std::vector<Entry>& entries) {
  std::string names;
  for (const Entry& entry : entries) names += (names.empty() ? "" : ", ") + std::string(entry.name);
  return names;
}

}  // namespace mufric
