// The CSV reader every command uses (calibrate's measurements, predict --csv, dataset and learn
// logs) against the files users bring (issue 72): a header cell is exactly name[unit], a name is
// one column's, a spreadsheet's byte-order mark is no part of the first name, and a semicolon file
// is named as such.
#include <fstream>

#include <gtest/gtest.h>

#include "common/csv_table.hpp"
#include "error_text.hpp"
#include "temp_path.hpp"

using namespace mufric;
using mufric::test::error_of;

namespace {
std::string file_with(const std::string& name, const std::string& text) {
  const std::string path = test::temp_path(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}
}  // namespace

TEST(CsvTable, TextAfterAHeaderCellsUnitIsAnErrorNamingTheCell) {
  const std::string sd = file_with("sd.csv", "temperature[C],temperature[C]_sd,mu[1]\n500,40,0.4\n");
  const std::string why = error_of([&] { read_csv_table(sd); });
  EXPECT_NE(why.find("'temperature[C]_sd'"), std::string::npos) << why;
  EXPECT_NE(why.find("temperature_sd[C]"), std::string::npos) << why;  // what was meant
  const std::string xyz = file_with("xyz.csv", "contact_pressure[MPa]xyz\n800\n");
  EXPECT_NE(error_of([&] { read_csv_table(xyz); }).find("'xyz' after its unit"), std::string::npos);
  const std::string open = file_with("open.csv", "contact_pressure[MPa\n800\n");
  EXPECT_NE(error_of([&] { read_csv_table(open); }).find("never closes"), std::string::npos);
}

TEST(CsvTable, TwoColumnsOfOneNameAreAnError) {
  const std::string path = file_with("twice.csv", "contact_pressure[MPa],mu[1],mu\n800,0.4,0.5\n");
  const std::string why = error_of([&] { read_csv_table(path); });
  EXPECT_NE(why.find("header cells 2 and 3 are both 'mu'"), std::string::npos) << why;
}

TEST(CsvTable, ASpreadsheetsByteOrderMarkIsStripped) {
  const std::string path = file_with("bom.csv", "\xEF\xBB\xBF" "contact_pressure[MPa],mu[1]\n800,0.4\n");
  const CsvTable t = read_csv_table(path);
  ASSERT_EQ(t.columns.size(), 2u);
  EXPECT_EQ(t.columns[0].name, "contact_pressure");
  EXPECT_EQ(t.si_column("contact_pressure").at(0), 800e6);
}

TEST(CsvTable, ASemicolonFileIsNamedAsSuch) {
  const std::string header = file_with("semi.csv", "contact_pressure[MPa];mu[1]\n554,4;0,41\n");
  const std::string why = error_of([&] { read_csv_table(header); });
  EXPECT_NE(why.find("seems to use ';'"), std::string::npos) << why;
  EXPECT_NE(why.find("decimal"), std::string::npos) << why;
  const std::string rows = file_with("semi_rows.csv", "contact_pressure[MPa],mu[1]\n554.4;0.41\n");
  EXPECT_NE(error_of([&] { read_csv_table(rows); }).find("seems to use ';'"), std::string::npos);
}

TEST(CsvTable, WellFormedHeadersStillRead) {
  const std::string path = file_with("good.csv", "# a comment\nFc (N), chip_ratio_exp_mean[1] ,x\n1,2,3\n");
  const CsvTable t = read_csv_table(path);
  ASSERT_EQ(t.columns.size(), 3u);
  EXPECT_EQ(t.columns[0].name, "Fc");
  EXPECT_EQ(t.columns[0].unit, "N");
  EXPECT_EQ(t.columns[1].name, "chip_ratio_exp_mean");
  EXPECT_EQ(t.columns[2].unit, "");
}

TEST(CsvTable, QuotedCellsHoldCommasAndOnlyTheAskedColumnsMustBeNumbers) {
  // A test log as a spreadsheet writes it: a quoted note with commas and "" quotes, an empty cell.
  const std::string path = file_with("log.csv",
                                     "speed[m/min],note,force[N],spare\n"
                                     "5,\"steady, after \"\"run-in\"\"\",105.5,\n"
                                     "10,plain,98.25,\n");
  const CsvTable table = read_csv_columns(path, {"force", "speed"});
  ASSERT_EQ(table.columns.size(), 2u);
  EXPECT_EQ(table.columns[0].name, "force");
  EXPECT_EQ(table.rows[0][0], 105.5);
  EXPECT_EQ(table.rows[1][1], 10.0);
  EXPECT_EQ(table.line_of_row[1], 3);
  // The whole table still wants every cell a number, and names the first that is not.
  EXPECT_NE(error_of([&] { read_csv_table(path); }).find("line 2, column 'note'"), std::string::npos);
  EXPECT_NE(error_of([&] { read_csv_columns(path, {"spare"}); }).find("line 2, column 'spare': '' is not a number"),
            std::string::npos);
}
