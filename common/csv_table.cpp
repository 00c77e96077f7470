#include "common/csv_table.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"

namespace mufric {
namespace {

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

// RFC 4180 cells: a cell in double quotes may hold commas, and "" inside it is one quote (how a
// spreadsheet writes a text column, e.g. a provenance note).
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"' && trim(cell).empty()) {
      quoted = true;
      cell.clear();
    } else if (c == ',') {
      cells.push_back(trim(cell));
      cell.clear();
    } else {
      cell += c;
    }
  }
  cells.push_back(trim(cell));
  return cells;
}

// "name[unit]" or "name (unit)" or "name", exactly: text after the unit's bracket is an error (a
// misplaced suffix such as "temperature[C]_sd" would otherwise read as a second "temperature").
CsvColumn parse_header_cell(const std::string& path, const std::string& cell) {
  for (const auto& [open, close] : {std::pair{'[', ']'}, std::pair{'(', ')'}}) {
    const auto a = cell.find(open);
    if (a == std::string::npos) continue;
    const auto b = cell.find(close, a);
    const std::string name = trim(cell.substr(0, a));
    if (b == std::string::npos) {
      throw Error(path + ": header cell '" + cell + "' opens its unit with '" + open + "' and never closes it");
    }
    const std::string unit = trim(cell.substr(a + 1, b - a - 1));
    const std::string after = trim(cell.substr(b + 1));
    if (!after.empty()) {
      throw Error(path + ": header cell '" + cell + "' has '" + after + "' after its unit: a cell is name" + open +
                  "unit" + close + " (did you mean '" + name + after + open + unit + close + "'?)");
    }
    if (name.empty()) throw Error(path + ": header cell '" + cell + "' has a unit but no name");
    return {name, unit};
  }
  return {cell, ""};
}

// What a spreadsheet writes as "CSV UTF-8": a byte-order mark before the first cell.
void strip_byte_order_mark(std::string& line) {
  if (line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
}

std::string semicolon_advice(const std::string& path) {
  return path + ": mufric reads comma-separated files, and this one seems to use ';' between cells (as spreadsheets "
                "write CSV where the decimal mark is a comma): save it with ',' between cells and '.' as the decimal mark";
}

}  // namespace

size_t CsvTable::column(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i) {
    if (columns[i].name == name) return i;
  }
  std::string present;
  for (const auto& c : columns) present += (present.empty() ? "" : ", ") + c.name;
  throw Error(path + ": no column '" + name + "' (columns: " + present + ")");
}

bool CsvTable::has_column(const std::string& name) const {
  for (const auto& c : columns) {
    if (c.name == name) return true;
  }
  return false;
}

std::vector<double> CsvTable::si_column(const std::string& name) const { return si_column(name, kind_of_input(name)); }

std::vector<double> CsvTable::si_column(const std::string& name, QuantityKind kind) const {
  const size_t j = column(name);
  const std::string& unit = columns[j].unit;
  if (unit.empty() && kind != QuantityKind::dimensionless) {
    throw Error(path + ": column '" + name + "' has no unit in the header; write e.g. '" + name + "[" +
                std::string(human_unit(kind)) + "]'");
  }
  UnitToSi map{kind, 1.0, 0.0};
  if (!unit.empty()) {
    try {
      map = unit_to_si(unit, kind);
    } catch (const Error& e) {
      throw Error(path + ": column '" + name + "': " + e.what());
    }
    if (kind != QuantityKind::dimensionless && map.kind != kind) {
      throw Error(path + ": column '" + name + "' has unit '" + unit + "', " + with_article(to_string(map.kind)) +
                  "; expected " + with_article(to_string(kind)));
    }
  }
  std::vector<double> values;
  values.reserve(rows.size());
  for (const auto& row : rows) values.push_back(map.scale * row[j] + map.offset);
  return values;
}

namespace {

// The header and every data row's cells as text, with the rows' line numbers.
struct CsvCells {
  std::vector<CsvColumn> columns;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> line_of_row;
};

CsvCells read_cells(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open (no such file or not readable)");
  CsvCells table;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line_number == 1) strip_byte_order_mark(line);
    const std::string content = trim(line);
    if (content.empty() || content.front() == '#') continue;
    auto cells = split(content);
    if (table.columns.empty()) {
      if (cells.size() == 1 && content.find(';') != std::string::npos) throw Error(semicolon_advice(path));
      for (const auto& cell : cells) {
        CsvColumn column = parse_header_cell(path, cell);
        for (size_t k = 0; k < table.columns.size(); ++k) {
          if (table.columns[k].name == column.name) {
            throw Error(path + ": header cells " + std::to_string(k + 1) + " and " + std::to_string(table.columns.size() + 1) +
                        " are both '" + column.name + "': each column needs a name of its own");
          }
        }
        table.columns.push_back(std::move(column));
      }
      continue;
    }
    if (cells.size() != table.columns.size()) {
      if (content.find(';') != std::string::npos) throw Error(semicolon_advice(path));
      throw Error(path + ": line " + std::to_string(line_number) + ": " + std::to_string(cells.size()) +
                  " cells, the header has " + std::to_string(table.columns.size()));
    }
    table.rows.push_back(std::move(cells));
    table.line_of_row.push_back(line_number);
  }
  if (table.columns.empty()) throw Error(path + ": empty file (no header line)");
  return table;
}

double parse_cell(const std::string& path, int line_number, const std::string& column, const std::string& cell) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (ec != std::errc() || end != cell.data() + cell.size() || cell.empty()) {
    throw Error(path + ": line " + std::to_string(line_number) + ", column '" + column + "': '" + cell +
                "' is not a number");
  }
  if (!std::isfinite(value)) {
    throw Error(path + ": line " + std::to_string(line_number) + ", column '" + column + "': " + cell +
                " is not a finite number");
  }
  return value;
}

// The numeric table of the columns at `indices` (in that order).
CsvTable numeric_table(const std::string& path, const CsvCells& cells, const std::vector<size_t>& indices) {
  CsvTable table;
  table.path = path;
  for (size_t j : indices) table.columns.push_back(cells.columns[j]);
  table.line_of_row = cells.line_of_row;
  for (size_t i = 0; i < cells.rows.size(); ++i) {
    std::vector<double> row;
    row.reserve(indices.size());
    for (size_t j : indices) row.push_back(parse_cell(path, cells.line_of_row[i], cells.columns[j].name, cells.rows[i][j]));
    table.rows.push_back(std::move(row));
  }
  return table;
}

}  // namespace

std::vector<double> CsvTable::si_difference_column(const std::string& name, QuantityKind kind) const {
  std::vector<double> values = si_column(name, kind);
  const std::string& unit = columns[column(name)].unit;
  const double offset = unit.empty() ? 0.0 : unit_to_si(unit, kind).offset;
  for (double& x : values) x -= offset;
  return values;
}

CsvTable read_csv_table(const std::string& path) {
  const CsvCells cells = read_cells(path);
  std::vector<size_t> every(cells.columns.size());
  for (size_t j = 0; j < every.size(); ++j) every[j] = j;
  return numeric_table(path, cells, every);
}

CsvTable read_csv_columns(const std::string& path, const std::vector<std::string>& names) {
  const CsvCells cells = read_cells(path);
  CsvTable header{path, cells.columns, {}, {}};
  std::vector<size_t> indices;
  for (const auto& name : names) indices.push_back(header.column(name));
  return numeric_table(path, cells, indices);
}

}  // namespace mufric
