#pragma once
// A module's options read by the module itself from its section of a structured file (a scene's
// JSON): typed reads with units and ranges, an error for a key left unread, and a record of keys that
// were read but took no effect (another law's coefficient, the lubricant's keys in a dry scene) which
// callers ask by key instead of matching a warning's text. Every error names the file and the key's
// path ("scene.json: contact.penalty: ..."). The pattern and an example: docs/design.md, "How a
// module takes its options".
#include <array>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/units.hpp"

namespace mufric {

// A word a file spells for an enum value: OptionChoice<E>::names (specialised beside E, in E's own
// module) lists them in the order messages give them; choice_name spells a value back.
template <class E>
struct NamedChoice {
  const char* name;
  E value;
};
template <class E>
struct OptionChoice;
// Declares E's word table, at global scope: MUFRIC_OPTION_WORDS(solid::TimeScheme, {"generalized-alpha",
// solid::TimeScheme::generalized_alpha}, {"quasi-static", solid::TimeScheme::quasi_static});
#define MUFRIC_OPTION_WORDS(E, ...)                                   \
  namespace mufric {                                                  \
  template <>                                                         \
  struct OptionChoice<E> {                                            \
    static constexpr NamedChoice<E> names[] = {__VA_ARGS__};          \
  };                                                                  \
  }
template <class E>
const char* choice_name(E value) {
  for (const auto& c : OptionChoice<E>::names) {
    if (c.value == value) return c.name;
  }
  return "unknown";
}

// What one reading of a file found besides the values: keys read but without effect, each with a
// line for the user. Shared by every section of the file.
// How a key was read, for the scene-key reference (`mufric micro keys`): its type with its unit's kind,
// the value an absent key takes, and its range or its words.
struct OptionKeyRead {
  std::string type;       // "pressure", "number", "integer", "true/false", "text", "word"
  std::string if_absent;  // in human units ("400MPa"); "" for a text without one
  std::string allowed;    // "[0.1MPa, 10GPa]", "one of: a, b"; "" when anything of the type is
  bool operator==(const OptionKeyRead&) const = default;
};

struct OptionReport {
  std::map<std::string, OptionKeyRead> reads;            // every key read, by full path, as it was read
  std::map<std::string, std::string> ineffective_keys;  // full path ("contact.shear_factor") → why
  std::vector<std::string> warnings;                     // one line each, no repeats
  void warn(const std::string& line);
};

class OptionKeys {
 public:
  // `object` must be a JSON object (an error names `path` otherwise); `source` names the file in
  // messages; `report` collects what the reads find. The keys reader keeps references to all three.
  OptionKeys(const nlohmann::json& object, std::string path, const std::string& source, OptionReport& report);

  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  // The key's full path ("contact.wetted.shear_factor"); the section's own for "".
  std::string name(const std::string& key) const;
  const std::string& source() const { return source_; }
  bool has(const std::string& key) const;

  // A dimensional value given as a string with its unit ("800MPa"), within [lo, hi] (SI).
  double quantity(const std::string& key, QuantityKind kind, double fallback, double lo, double hi);
  double number(const std::string& key, double fallback, double lo, double hi);
  int integer(const std::string& key, int fallback, int lo, int hi);
  bool boolean(const std::string& key, bool fallback);
  // A string; one of `allowed` when that is not empty.
  std::string text(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed);
  // A word from the choice's one table (OptionChoice<E>::names).
  template <class E>
  E choice(const std::string& key, E fallback) {
    std::string words;
    for (const auto& c : OptionChoice<E>::names) words += (words.empty() ? "" : ", ") + std::string(c.name);
    record(key, {"word", choice_name(fallback), "one of: " + words});
    const nlohmann::json* v = take(key);
    if (v == nullptr) return fallback;
    if (!v->is_string()) fail(key, "must be a string");
    const auto word = v->get<std::string>();
    for (const auto& c : OptionChoice<E>::names) {
      if (word == c.name) return c.value;
    }
    fail(key, "'" + word + "' is not one of: " + words);
  }
  // A subsection (an empty one where the key is absent).
  OptionKeys child(const std::string& key);
  // A present key that this reading leaves without effect: taken (no "unknown key"), recorded in the
  // report with a warning "PATH is read but has no effect: WHY". Nothing when the key is absent.
  void ineffective(const std::string& key, const std::string& why);
  // Unknown keys (not read) are errors naming the first.
  void finish() const;
  OptionReport& report() const { return report_; }

 private:
  const nlohmann::json* take(const std::string& key);
  void record(const std::string& key, OptionKeyRead read);
  const nlohmann::json& j_;
  std::string path_;
  const std::string& source_;
  OptionReport& report_;
  std::set<std::string> used_;
};

}  // namespace mufric
