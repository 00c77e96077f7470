#pragma once
// The reductions' setups (JSON): reading a field with its unit, a fixed value or a range, the tests'
// uncertainty columns and their column names, and writing the outputs' numbers and comments. Errors
// name the setup's file and the field.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/csv_table.hpp"
#include "common/units.hpp"
#include "surrogate/reduction/orthogonal_cutting.hpp"  // ValueRange
#include "surrogate/reduction/test_groups.hpp"

namespace mufric::reduction_setup {

// °C = K − this.
inline constexpr double kCelsiusOffset = 273.15;

// The setup file's JSON (Error naming the file when it cannot be read or parsed).
nlohmann::json read_setup(const std::string& path);

const nlohmann::json& required(const nlohmann::json& setup, const std::string& key, const std::string& path);
double number_field(const nlohmann::json& setup, const std::string& key, const std::string& path);
// "15deg", "1mm", "293K": a quantity with its unit.
double quantity_field(const nlohmann::json& setup, const std::string& key, QuantityKind kind, const std::string& path);
// A number (fixed) or [low, high] (uniform).
ValueRange range_field(const nlohmann::json& setup, const std::string& key, const std::string& path);
// A quantity with its unit (fixed) or ["2.5GPa", "3.5GPa"] (uniform), SI.
ValueRange quantity_range_field(const nlohmann::json& setup, const std::string& key, QuantityKind kind, const std::string& path);

// How the tests' uncertainty columns are meant: a mean's standard error, the repeats' SD, or an
// error bar of twice their SD (the figures of data/cirp2022_ti6al4v_tin).
enum class UncertaintyKind { standard_error, sd, two_sd };
UncertaintyKind uncertainty_kind(const std::string& word, const std::string& path);
std::string suffix_of(UncertaintyKind kind);
// The setup's "uncertainty" and "repeats" (repeats needed unless the columns are standard errors).
struct Uncertainty {
  UncertaintyKind kind = UncertaintyKind::sd;
  double repeats = 1.0;
  // A cell of an uncertainty column as the standard error of its mean.
  double standard_error(double cell) const;
};
Uncertainty uncertainty_of(const nlohmann::json& setup, const std::string& path);

// The header cell's name of each role: the setup's "columns" or the role's own name.
std::string column_of(const nlohmann::json& setup, const std::string& role, const std::string& fallback);
// N per unit of a force column's header unit (N or kN; Error naming the column otherwise).
double force_scale(const CsvTable& table, const std::string& name);

// printf's %.<digits>g, as the outputs print numbers.
std::string g_text(double value, int digits);
// The pattern with "{}" replaced by the value (%.6g).
std::string with_value(const std::string& pattern, double value);
// Each line as a "# " comment line.
std::string comment_block(const std::vector<std::string>& lines);
// The setup's "provenance" lines.
std::vector<std::string> provenance_of(const nlohmann::json& setup);

// The setup's "tests" CSV, relative to the setup's folder.
std::string tests_path_of(const nlohmann::json& setup, const std::string& setup_path);
// The setup's "group": its column and calibrated groups (the header and label need the table).
TestGroups groups_of(const nlohmann::json& setup);
// The group column's header cell from the read table, and the label (default "HEADER {}").
void name_groups(TestGroups& groups, const CsvTable& table, const nlohmann::json& setup);
// A row's group (0 without a group column).
double group_of_row(const TestGroups& groups, const CsvTable& table, size_t row);

// The Monte Carlo's "draws" and "seed", where the setup gives them.
template <typename MonteCarloSetup>
void read_draws(const nlohmann::json& setup, MonteCarloSetup& s) {
  s.draws = setup.value("draws", s.draws);
  s.seed = setup.value("seed", s.seed);
}
// "20000 draws, seed 2026.", as the outputs' comment says it.
std::string draws_sentence(int draws, std::uint32_t seed);

}  // namespace mufric::reduction_setup
