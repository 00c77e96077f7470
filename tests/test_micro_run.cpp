// The dry micro-model end to end on small scenes: scene validation names the key; a flat tool
// transmits no tangential force (μ = 0); shifting both surfaces along the interval leaves μ
// unchanged; a mirror-symmetric configuration reverses μ with the sliding direction.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "common/error.hpp"
#include "micro/scene/micro_run.hpp"

namespace mufric::scene {
namespace {

// The default scene made small and short: a coarse mesh, 1 ns steps, 20 ns with a 10 ns ramp.
nlohmann::json small_scene() {
  nlohmann::json j = default_scene_json();
  for (const char* s : {"discretisation.elements_x=32", "discretisation.elements_y=4",
                        "geometry.chip_surface.fit.control_points=32", "geometry.tool_surface.fit.control_points=32",
                        "time.duration=\"20ns\"", "time.average_from=\"10ns\"", "load.ramp=\"10ns\"",
                        "load.pressure=\"400MPa\""}) {
    apply_override(j, s);
  }
  return j;
}

std::string error_of(const nlohmann::json& j) {
  try {
    parse_scene(j, "scene.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, ErrorsNameTheKey) {
  const nlohmann::json j = default_scene_json();
  EXPECT_NO_THROW(parse_scene(j, "scene.json"));
  // The message of the error a single override provokes, and the part it must contain.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"load.presure=\"800MPa\"", "load.presure: unknown key"},
      {"load.pressure=800", "load.pressure"},  // no unit
      {"discretisation.degree=9", "discretisation.degree: 9 is outside"},
      {"physics=lubricated", "not implemented yet"},
      {"time.average_from=\"1s\"", "time.average_from"},
      {"time.max_step=\"0.5ns\"", "time.max_step: is shorter than time.step"},
      {"geometry.chip_surface.flat=true", "exactly one of csv, synthetic or flat"}};
  for (const auto& [assignment, expected] : cases) {
    nlohmann::json bad = j;
    apply_override(bad, assignment);
    EXPECT_NE(error_of(bad).find(expected), std::string::npos) << assignment << ": " << error_of(bad);
  }
  nlohmann::json kelvin = j;
  apply_override(kelvin, "load.temperature=500K");
  EXPECT_DOUBLE_EQ(parse_scene(kelvin, "s").temperature, 500.0);
  EXPECT_THROW(apply_override(kelvin, "novalue"), Error);
}

// Regression (fuzz_scene_json): a number JSON cannot hold (1e999...) threw nlohmann's out_of_range,
// which nothing caught, from a scene file and from a --set override. Both are now an Error or a
// value the key's own check refuses; the fuzzer's inputs are replayed as a file and as an override.
TEST(Scene, NumbersJsonCannotHoldAreErrors) {
  EXPECT_THROW(scene_with_overrides(default_scene_json(), {"load.pressure=1e999"}, "test"), Error);
  const std::string path = (std::filesystem::temp_directory_path() / "mufric_overflow_scene.json").string();
  std::ofstream(path) << R"({"physics": "dry", "contact": {"penalty": 1e999}})";
  EXPECT_THROW(load_scene(path, {}), Error);
  std::filesystem::remove(path);
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(MUFRIC_SOURCE_DIR) / "tests/fuzz/regressions/fuzz_scene_json")) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    try {
      load_scene(entry.path().string(), {});
    } catch (const Error&) {
    }
    try {
      scene_with_overrides(default_scene_json(), {bytes.str()}, "fuzz");
    } catch (const Error&) {
    }
  }
}

TEST(MicroRun, FlatToolTransmitsNoTangentialForce) {
  nlohmann::json j = small_scene();
  j["geometry"]["tool_surface"] = {{"flat", true}, {"fit", {{"degree", 3}, {"control_points", 32}}}};
  const MicroResult r = run_micro(parse_scene(j, "flat"));
  ASSERT_TRUE(r.completed) << r.reason;
  EXPECT_GT(r.contact_fraction, 0.0);
  // Every tool normal is vertical: no tangential force beyond rounding.
  EXPECT_LT(std::abs(r.mu), 1e-12);
  for (const auto& s : r.history) EXPECT_LE(std::abs(s.force.x()), 1e-12 * std::abs(s.force.y()));
}

TEST(MicroRun, ShiftingBothSurfacesAlongTheIntervalLeavesMuUnchanged) {
  const MicroResult base = run_micro(parse_scene(small_scene(), "base"));
  ASSERT_TRUE(base.completed) << base.reason;
  nlohmann::json j = small_scene();
  apply_override(j, "geometry.chip_surface.shift=0.37");
  apply_override(j, "geometry.tool_surface.shift=0.37");
  const MicroResult shifted = run_micro(parse_scene(j, "shifted"));
  ASSERT_TRUE(shifted.completed) << shifted.reason;
  EXPECT_GT(std::abs(base.mu), 1e-3);
  ASSERT_TRUE(base.solver.cutbacks.empty() && shifted.solver.cutbacks.empty());  // the same steps, or the comparison says nothing
  EXPECT_NEAR(shifted.mu, base.mu, 1e-6 * std::abs(base.mu));
  EXPECT_NEAR(shifted.contact_fraction, base.contact_fraction, 1e-6);
}

// Even profiles (cosine teeth) about x = 0: reversing the sliding direction is the mirror image.
TEST(MicroRun, SymmetricTeethReverseMuWithTheSlidingDirection) {
  const auto dir = std::filesystem::temp_directory_path() / ("mufric_teeth_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, auto height) {
    std::ofstream out(dir / name);
    out << "x[um],height[um]\n" << std::setprecision(17);
    for (int k = 0; k < 512; ++k) {
      const double x = 10.0 * k / 512;
      out << x << "," << height(2 * std::numbers::pi * x / 10.0) << "\n";
    }
  };
  write("chip.csv", [](double a) { return 0.15 * std::cos(3 * a) + 0.05 * std::cos(5 * a); });
  write("tool.csv", [](double a) { return -0.2 * std::cos(a) + 0.05 * std::cos(4 * a); });
  auto scene_for = [&](const std::string& velocity) {
    nlohmann::json j = small_scene();
    j["geometry"]["chip_surface"] = {{"csv", (dir / "chip.csv").string()}, {"fit", {{"degree", 3}, {"control_points", 32}}}};
    j["geometry"]["tool_surface"] = {{"csv", (dir / "tool.csv").string()}, {"fit", {{"degree", 3}, {"control_points", 32}}}};
    apply_override(j, "load.velocity=\"" + velocity + "\"");
    return parse_scene(j, "teeth");
  };
  const MicroResult forward = run_micro(scene_for("200m/min")), backward = run_micro(scene_for("-200m/min"));
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(forward.completed) << forward.reason;
  ASSERT_TRUE(backward.completed) << backward.reason;
  EXPECT_GT(std::abs(forward.mu), 1e-3);
  EXPECT_NEAR(backward.mu, -forward.mu, 1e-6 * std::abs(forward.mu));
}

// The default scene on a coarser mesh and a shorter window: the chip closes onto the tool, peaks
// flatten plastically, heat up, and the tool resists the sliding (μ > 0).
TEST(MicroRun, DefaultSceneSmokeTest) {
  nlohmann::json j = default_scene_json();
  for (const char* s : {"discretisation.elements_x=64", "discretisation.elements_y=6", "time.duration=\"60ns\"",
                        "time.average_from=\"40ns\""}) {
    apply_override(j, s);
  }
  const Scene scene = parse_scene(j, "default, coarse");
  const MicroResult r = run_micro(scene);
  ASSERT_TRUE(r.completed) << r.reason;
  EXPECT_TRUE(std::isfinite(r.mu));
  EXPECT_GT(r.mu, 0.0);
  EXPECT_LT(r.mu, 1.0);
  EXPECT_GT(r.contact_fraction, 0.2);  // pressed at 800 MPa, well above the 500 °C yield stress
  EXPECT_GT(r.max_plastic_strain, 0.1);
  EXPECT_GT(r.max_temperature, scene.temperature);  // adiabatic heating of the flattened peaks
  EXPECT_GT(r.max_contact_pressure, scene.pressure);
  EXPECT_FALSE(r.history.front().mu.has_value() && r.history.front().contact_fraction > 0.5);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
}

TEST(MicroRun, AChipAtItsMeltingTemperatureIsReportedOutsideTheModel) {
  nlohmann::json j = small_scene();
  for (const char* s : {"discretisation.elements_x=16", "geometry.chip_surface.fit.control_points=16",
                        "time.duration=\"6ns\"", "time.average_from=\"3ns\"", "load.ramp=\"3ns\"",
                        "load.temperature=\"1500C\""}) {
    apply_override(j, s);
  }
  const MicroResult r = run_micro(parse_scene(j, "molten"));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings.front().find("melting temperature"), std::string::npos) << r.warnings.front();
  EXPECT_EQ(r.to_json(parse_scene(j, "molten"))["warnings"].size(), 1u);
}

}  // namespace
}  // namespace mufric::scene
