#include "surrogate/reduction/setup_fields.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/error.hpp"

namespace mufric::reduction_setup {

std::string g_text(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

std::string with_value(const std::string& pattern, double value) {
  const auto at = pattern.find("{}");
  if (at == std::string::npos) return pattern;
  return pattern.substr(0, at) + g_text(value, 6) + pattern.substr(at + 2);
}

const nlohmann::json& required(const nlohmann::json& setup, const std::string& key, const std::string& path) {
  if (!setup.contains(key)) throw Error(path + ": the setup has no '" + key + "'");
  return setup.at(key);
}

double number_field(const nlohmann::json& setup, const std::string& key, const std::string& path) {
  const auto& node = required(setup, key, path);
  if (!node.is_number()) throw Error(path + ": '" + key + "' must be a number, not " + node.dump());
  return node.get<double>();
}

double quantity_field(const nlohmann::json& setup, const std::string& key, QuantityKind kind, const std::string& path) {
  const auto& node = required(setup, key, path);
  if (!node.is_string())
    throw Error(path + ": '" + key + "' must be a quantity with its unit, e.g. \"" + std::string(example_quantity(kind)) + "\"");
  return parse_quantity(node.get<std::string>(), kind, path + ": '" + key + "'");
}

ValueRange range_field(const nlohmann::json& setup, const std::string& key, const std::string& path) {
  const auto& node = required(setup, key, path);
  if (node.is_number()) return {node.get<double>(), node.get<double>()};
  if (node.is_array() && node.size() == 2 && node[0].is_number() && node[1].is_number()) return {node[0].get<double>(), node[1].get<double>()};
  throw Error(path + ": '" + key + "' must be a number or a range [low, high], not " + node.dump());
}

UncertaintyKind uncertainty_kind(const std::string& word, const std::string& path) {
  if (word == "se") return UncertaintyKind::standard_error;
  if (word == "sd") return UncertaintyKind::sd;
  if (word == "2sd") return UncertaintyKind::two_sd;
  throw Error(path + ": 'uncertainty' is '" + word + "'; it must be se (the mean's standard error), sd (the repeats' SD) or 2sd (twice it)");
}

std::string suffix_of(UncertaintyKind kind) {
  switch (kind) {
    case UncertaintyKind::standard_error: return "_se";
    case UncertaintyKind::sd: return "_sd";
    case UncertaintyKind::two_sd: return "_2sd";
  }
  return "_sd";
}

std::string column_of(const nlohmann::json& setup, const std::string& role, const std::string& fallback) {
  if (setup.contains("columns") && setup["columns"].contains(role)) return setup["columns"][role].get<std::string>();
  return fallback;
}

double force_scale(const CsvTable& table, const std::string& name) {
  const std::string& unit = table.columns[table.column(name)].unit;
  if (unit == "N") return 1.0;
  if (unit == "kN") return 1e3;
  throw Error(table.path + ": column '" + name + "' has unit '" + unit + "'; a force is in N or kN, e.g. '" + name + "[N]'");
}


std::string comment_block(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += "# " + line + "\n";
  return text;
}

nlohmann::json read_setup(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open (no such file or not readable)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path + ": not JSON: " + e.what());
  }
}

ValueRange quantity_range_field(const nlohmann::json& setup, const std::string& key, QuantityKind kind, const std::string& path) {
  const auto& node = required(setup, key, path);
  const std::string field = path + ": '" + key + "'";
  if (node.is_string()) {
    const double value = parse_quantity(node.get<std::string>(), kind, field);
    return {value, value};
  }
  if (node.is_array() && node.size() == 2 && node[0].is_string() && node[1].is_string())
    return {parse_quantity(node[0].get<std::string>(), kind, field), parse_quantity(node[1].get<std::string>(), kind, field)};
  throw Error(field + " must be a quantity with its unit or a range of two, e.g. \"" + std::string(example_quantity(kind)) + "\"");
}

double Uncertainty::standard_error(double cell) const {
  switch (kind) {
    case UncertaintyKind::standard_error: return cell;
    case UncertaintyKind::sd: return cell / std::sqrt(repeats);
    case UncertaintyKind::two_sd: return cell / 2.0 / std::sqrt(repeats);
  }
  return cell;
}

Uncertainty uncertainty_of(const nlohmann::json& setup, const std::string& path) {
  Uncertainty u;
  u.kind = uncertainty_kind(setup.value("uncertainty", std::string("sd")), path);
  u.repeats = u.kind == UncertaintyKind::standard_error ? 1.0 : number_field(setup, "repeats", path);
  if (!(u.repeats >= 1.0)) throw Error(path + ": 'repeats' must be at least 1");
  return u;
}

std::vector<std::string> provenance_of(const nlohmann::json& setup) {
  std::vector<std::string> lines;
  for (const auto& line : setup.value("provenance", nlohmann::json::array())) lines.push_back(line.get<std::string>());
  return lines;
}

std::string tests_path_of(const nlohmann::json& setup, const std::string& setup_path) {
  return (std::filesystem::path(setup_path).parent_path() / required(setup, "tests", setup_path).get<std::string>()).string();
}

TestGroups groups_of(const nlohmann::json& setup) {
  TestGroups groups;
  if (!setup.contains("group")) return groups;
  groups.column = setup["group"].value("column", std::string());
  for (const auto& g : setup["group"].value("calibrate", nlohmann::json::array())) groups.calibrated.push_back(g.get<double>());
  return groups;
}

void name_groups(TestGroups& groups, const CsvTable& table, const nlohmann::json& setup) {
  if (groups.column.empty()) return;
  const auto& column = table.columns[table.column(groups.column)];
  groups.header = column.unit.empty() ? column.name : column.name + "[" + column.unit + "]";
  groups.label = setup["group"].value("label", groups.header + " {}");
}

double group_of_row(const TestGroups& groups, const CsvTable& table, size_t row) {
  return groups.column.empty() ? 0.0 : table.rows[row][table.column(groups.column)];
}

std::string draws_sentence(int draws, std::uint32_t seed) {
  return std::to_string(draws) + " draws, seed " + std::to_string(seed) + ".";
}

}  // namespace mufric::reduction_setup
