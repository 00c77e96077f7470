#pragma once
// A numeric CSV table whose header names each column and its unit: "contact_pressure[MPa],mu".
// Lines starting with '#' are comments; a cell in double quotes may hold commas. Errors name the
// file, line and column.
#include <string>
#include <vector>

#include "common/units.hpp"

namespace mufric {

struct CsvColumn {
  std::string name;
  std::string unit;  // as written in the header; empty when none was given
};

struct CsvTable {
  std::string path;
  std::vector<CsvColumn> columns;
  std::vector<std::vector<double>> rows;  // raw values in the header's units
  std::vector<int> line_of_row;           // 1-based line number in the file, for messages

  // Index of the column called `name`; throws Error naming the file and the columns present.
  size_t column(const std::string& name) const;
  bool has_column(const std::string& name) const;
  // Column values converted to SI using the header unit; throws if the unit is missing or unknown.
  std::vector<double> si_column(const std::string& name) const;
  // The same for a column that must carry a unit of `kind` (a profile's x and height: lengths),
  // whatever its name says.
  std::vector<double> si_column(const std::string& name, QuantityKind kind) const;
  // A column of differences (an SD, a half-width) in SI: scaled like si_column but without the
  // unit's offset, so a temperature SD in °C is the same number of kelvin.
  std::vector<double> si_difference_column(const std::string& name, QuantityKind kind) const;
};

// Parses `path`; every cell must be a finite number. Throws Error naming line and column.
CsvTable read_csv_table(const std::string& path);
// Only the columns called `names`, in that order, each cell a finite number; the file's other
// columns may hold text or be empty (a test log with a notes column). A missing column throws Error
// naming the file and the columns present.
CsvTable read_csv_columns(const std::string& path, const std::vector<std::string>& names);

}  // namespace mufric
