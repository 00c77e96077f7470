#include <gtest/gtest.h>

#include <cmath>

#include "common/error.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"

namespace mufric {
namespace {

TEST(Units, ParsesHumanQuantitiesToSi) {
  EXPECT_DOUBLE_EQ(parse_quantity("800MPa", QuantityKind::pressure, "--p"), 800e6);
  EXPECT_DOUBLE_EQ(parse_quantity(" 1.3 GPa", QuantityKind::pressure, "--p"), 1.3e9);
  EXPECT_DOUBLE_EQ(parse_quantity("120m/min", QuantityKind::velocity, "--v"), 2.0);
  EXPECT_DOUBLE_EQ(parse_quantity("500C", QuantityKind::temperature, "--T"), 773.15);
  EXPECT_DOUBLE_EQ(parse_quantity("25°C", QuantityKind::temperature, "--T"), 298.15);
  EXPECT_DOUBLE_EQ(parse_quantity("300K", QuantityKind::temperature, "--T"), 300.0);
  EXPECT_NEAR(parse_quantity("90deg", QuantityKind::angle, "--angle"), 1.5707963267948966, 1e-15);
}

std::string message_of(const std::string& text, QuantityKind kind) {
  try {
    parse_quantity(text, kind, "--p");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Units, NumberWithoutUnitIsAnErrorNamingTheField) {
  const std::string m = message_of("800", QuantityKind::pressure);
  EXPECT_NE(m.find("--p"), std::string::npos);
  EXPECT_NE(m.find("no unit"), std::string::npos);
}

TEST(Units, UnknownAndWrongKindUnitsAreErrors) {
  EXPECT_NE(message_of("800psi", QuantityKind::pressure).find("unknown unit 'psi'"), std::string::npos);
  EXPECT_NE(message_of("800m/s", QuantityKind::pressure).find("is a velocity, expected a pressure"), std::string::npos);
  // Regression (issue 30): "is a angle", "expected a angle".
  EXPECT_NE(message_of("90deg", QuantityKind::pressure).find("is an angle, expected a pressure"), std::string::npos);
  EXPECT_NE(message_of("800MPa", QuantityKind::angle).find("is a pressure, expected an angle such as"), std::string::npos);
  EXPECT_NE(message_of("90", QuantityKind::angle).find("has no unit; an angle needs one"), std::string::npos);
  EXPECT_NE(message_of("abc", QuantityKind::pressure).find("not a number"), std::string::npos);
  EXPECT_NE(message_of("nanMPa", QuantityKind::pressure).find("not a number"), std::string::npos);
}

// Issue 72: "10m/mn" and "1,5GPa" got "unknown unit" and nothing more.
TEST(Units, AMistypedUnitGetsTheNearestKnownOneAndADecimalCommaIsNamed) {
  EXPECT_NE(message_of("10m/mn", QuantityKind::velocity).find("unknown unit 'm/mn'; did you mean 'm/min'?"), std::string::npos)
      << message_of("10m/mn", QuantityKind::velocity);
  // the case alone: "Mpa" is MPa, not the nearer-by-edits "Pa"
  EXPECT_NE(message_of("800Mpa", QuantityKind::pressure).find("did you mean 'MPa'?"), std::string::npos);
  EXPECT_NE(message_of("800mpa", QuantityKind::pressure).find("did you mean 'MPa'?"), std::string::npos);
  // a unit of the wanted kind before a nearer one of another: "Gpq" for a pressure is GPa
  EXPECT_NE(message_of("1Gpq", QuantityKind::pressure).find("did you mean 'GPa'?"), std::string::npos);
  EXPECT_NE(message_of("500degK", QuantityKind::temperature).find("did you mean 'degC'?"), std::string::npos);
  // nothing near: no guess
  EXPECT_EQ(message_of("800psi", QuantityKind::pressure).find("did you mean"), std::string::npos);
  const std::string comma = message_of("1,5GPa", QuantityKind::pressure);
  EXPECT_NE(comma.find("--p: '1,5GPa' has a decimal comma; mufric reads a decimal point: '1.5GPa'"), std::string::npos) << comma;
  EXPECT_NE(message_of("12,5 m/min", QuantityKind::velocity).find("'12.5 m/min'"), std::string::npos);
}

TEST(Wording, EditDistanceCountsSwapsAsOneEdit) {
  EXPECT_EQ(edit_distance("predcit", "predict"), 1u);
  EXPECT_EQ(edit_distance("m/mn", "m/min"), 1u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);  // the textbook case
  EXPECT_EQ(nearest_word("serv", {"predict", "serve", "server"}, 2), "serve");
  EXPECT_EQ(nearest_word("xyz", {"predict", "serve"}, 2), "");
}

TEST(Wording, CountsAndArticles) {
  EXPECT_EQ(count_of(1, "file", "files"), "1 file");
  EXPECT_EQ(count_of(0, "file", "files"), "0 files");
  EXPECT_EQ(count_of(3, "evaluation thread", "evaluation threads"), "3 evaluation threads");
  EXPECT_EQ(with_article("angle"), "an angle");
  EXPECT_EQ(with_article("pressure"), "a pressure");
}

TEST(Units, FormatsInHumanUnits) {
  EXPECT_EQ(format_human(800e6, QuantityKind::pressure), "800MPa");
  EXPECT_EQ(format_human(2.0, QuantityKind::velocity), "120m/min");
  EXPECT_EQ(format_human(773.15, QuantityKind::temperature), "500°C");
}

// One table of physical ranges for every command: the edges are inside, just beyond them is not, and
// the message names the value in human units.
TEST(Units, PhysicalRangesRefuseImpossibleValuesWithAReason) {
  EXPECT_EQ(physical_range_violation(800e6, QuantityKind::pressure), "");
  EXPECT_EQ(physical_range_violation(0.0, QuantityKind::pressure), "");
  EXPECT_EQ(physical_range_violation(0.0, QuantityKind::temperature), "");
  EXPECT_EQ(physical_range_violation(-3.0, QuantityKind::angle), "");  // angles are periodic, unbounded
  EXPECT_NE(physical_range_violation(-1e-9, QuantityKind::pressure), "");
  EXPECT_NE(physical_range_violation(-0.1, QuantityKind::velocity), "");
  EXPECT_NE(physical_range_violation(101e9, QuantityKind::pressure), "");
  EXPECT_NE(physical_range_violation(std::nan(""), QuantityKind::angle), "");
  EXPECT_EQ(physical_range_violation(-400.0 + 273.15, QuantityKind::temperature), "-400°C is below absolute zero (-273.15°C)");
  EXPECT_EQ(physical_range_violation(-500e6, QuantityKind::pressure), "-500MPa is below 0MPa, the least a pressure can be");
}

}  // namespace
}  // namespace mufric
