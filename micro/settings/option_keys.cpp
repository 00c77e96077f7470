#include "micro/settings/option_keys.hpp"

#include <algorithm>
#include <sstream>

#include "common/error.hpp"

namespace mufric {

using nlohmann::json;

void OptionReport::warn(const std::string& line) {
  if (std::find(warnings.begin(), warnings.end(), line) == warnings.end()) warnings.push_back(line);
}

OptionKeys::OptionKeys(const json& object, std::string path, const std::string& source, OptionReport& report)
    : j_(object), path_(std::move(path)), source_(source), report_(report) {
  if (!j_.is_object()) fail("", "must be an object");
}

void OptionKeys::fail(const std::string& key, const std::string& message) const {
  throw Error(source_ + ": " + name(key) + ": " + message);
}

std::string OptionKeys::name(const std::string& key) const {
  return path_.empty() ? key : key.empty() ? path_ : path_ + "." + key;
}

bool OptionKeys::has(const std::string& key) const { return j_.contains(key); }

const json* OptionKeys::take(const std::string& key) {
  used_.insert(key);
  return j_.contains(key) ? &j_.at(key) : nullptr;
}

void OptionKeys::record(const std::string& key, OptionKeyRead read) { report_.reads[name(key)] = std::move(read); }

namespace {
std::string plain_number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}
}  // namespace

double OptionKeys::quantity(const std::string& key, QuantityKind kind, double fallback, double lo, double hi) {
  record(key, {std::string(to_string(kind)), format_human(fallback, kind),
               "[" + format_human(lo, kind) + ", " + format_human(hi, kind) + "]"});
  const json* v = take(key);
  if (v == nullptr) return fallback;
  if (!v->is_string()) fail(key, "give a value with its unit as a string, e.g. \"" + std::string(example_quantity(kind)) + "\"");
  double x = 0.0;
  try {
    x = parse_quantity(v->get<std::string>(), kind, name(key));
  } catch (const Error& e) {
    throw Error(source_ + ": " + e.what());  // the file too, as for every other key's error
  }
  if (!(x >= lo && x <= hi)) {
    fail(key, v->get<std::string>() + " is outside [" + format_human(lo, kind) + ", " + format_human(hi, kind) + "]");
  }
  return x;
}

double OptionKeys::number(const std::string& key, double fallback, double lo, double hi) {
  record(key, {"number", plain_number(fallback), "[" + plain_number(lo) + ", " + plain_number(hi) + "]"});
  const json* v = take(key);
  if (v == nullptr) return fallback;
  if (!v->is_number()) fail(key, "must be a number");
  const double x = v->get<double>();
  if (!(x >= lo && x <= hi)) fail(key, std::to_string(x) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

int OptionKeys::integer(const std::string& key, int fallback, int lo, int hi) {
  record(key, {"integer", std::to_string(fallback), "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]"});
  const json* v = take(key);
  if (v == nullptr) return fallback;
  if (!v->is_number_integer()) fail(key, "must be an integer");
  const auto x = v->get<long long>();
  if (x < lo || x > hi) fail(key, std::to_string(x) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<int>(x);
}

bool OptionKeys::boolean(const std::string& key, bool fallback) {
  record(key, {"true/false", fallback ? "true" : "false", ""});
  const json* v = take(key);
  if (v == nullptr) return fallback;
  if (!v->is_boolean()) fail(key, "must be true or false");
  return v->get<bool>();
}

std::string OptionKeys::text(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed) {
  std::string words;
  for (const auto& a : allowed) words += (words.empty() ? "" : ", ") + a;
  record(key, {"text", fallback, words.empty() ? "" : "one of: " + words});
  const json* v = take(key);
  if (v == nullptr) return fallback;
  if (!v->is_string()) fail(key, "must be a string");
  const auto s = v->get<std::string>();
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), s) == allowed.end()) {
    fail(key, "'" + s + "' is not one of: " + words);
  }
  return s;
}

OptionKeys OptionKeys::child(const std::string& key) {
  static const json empty = json::object();
  const json* v = take(key);
  return OptionKeys(v ? *v : empty, name(key), source_, report_);
}

void OptionKeys::ineffective(const std::string& key, const std::string& why) {
  if (!has(key)) return;
  take(key);
  report_.ineffective_keys.emplace(name(key), why);
  report_.warn(name(key) + " is read but has no effect: " + why);
}

void OptionKeys::finish() const {
  for (const auto& [key, value] : j_.items()) {
    if (!used_.count(key)) fail(key, "unknown key");
  }
}

}  // namespace mufric
