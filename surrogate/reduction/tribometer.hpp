#pragma once
// From pin-on-disc or open-tribometer tests (a spherical pin or ball rubbing the work material) to
// the interface's friction: each test's apparent μ (tangential over normal force) less the pin's
// ploughing, by Goddard & Wilman's (1962, Wear 5:114) rigid sphere ploughing a rigid-plastic surface:
// the load carried by the front half of the contact circle at the work's flow pressure p,
// F_n = p π a²/2, the ploughing force p times the groove's frontal area, so
//   μ_p = (2/π) [(R/a)² asin(a/R) − √((R/a)² − 1)],
// with the contact pressure p the interface's. The uncertainty by Monte Carlo (NumPy's stream): the
// apparent μ from its standard error, p uniform over its range. Or the ploughing left in, stated: the
// rows are then the apparent μ, which includes the pin's ploughing.
#include <optional>
#include <string>
#include <vector>

#include "surrogate/reduction/orthogonal_cutting.hpp"  // MeasuredMean, ValueRange, McEstimate
#include "surrogate/reduction/test_groups.hpp"
#include "surrogate/reduction/written_table.hpp"

namespace mufric {

// One test, SI.
struct TribometerTest {
  double group = 0.0;
  double sliding_velocity = 0.0;                 // m/s
  double normal_force = 0.0;                     // N
  MeasuredMean mu_apparent;                      // tangential over normal force
  std::optional<double> contact_pressure;        // Pa, where the test states it (else the flow pressure)
  std::optional<MeasuredMean> temperature;       // K, where measured or estimated
  std::string row_name;
};

enum class PloughingCorrection { goddard_wilman, none };

struct TribometerSetup {
  double pin_radius = 0.0;  // m
  ValueRange flow_pressure;  // Pa: the work material's mean pressure under a plastic indentation (≈ its hardness), uniform
  PloughingCorrection ploughing = PloughingCorrection::goddard_wilman;
  int draws = 20000;
  std::uint32_t seed = 2026;
};

struct TribometerEstimate {
  double group = 0.0, sliding_velocity = 0.0;
  McEstimate mu_apparent, mu_ploughing, mu;    // mu: the interface's (apparent less ploughing, or apparent)
  McEstimate contact_pressure, contact_radius;  // Pa, m
  std::optional<MeasuredMean> temperature;
  std::string row_name;
};

// Goddard & Wilman's ploughing coefficient of a sphere at contact radius over sphere radius x ∈ (0, 1].
double sphere_ploughing_coefficient(double x);

// Each test in the file's order. Throws Error naming the row when a contact does not fit the pin
// (a ≥ R) or a value is not physical.
std::vector<TribometerEstimate> friction_from_tribometer(const std::vector<TribometerTest>& tests, const TribometerSetup& setup);

// The setup (JSON) and its tests, as read; the analysis and calibration tables as text.
struct TribometerStudy {
  TribometerSetup setup;
  std::vector<TribometerTest> tests;
  std::string setup_path, tests_path;
  TestGroups groups;
  std::vector<std::string> provenance;
  std::string analysis_file = "tribometer_analysis.csv";
  std::string calibration_file = "tribometer_mu.csv";
};
TribometerStudy read_tribometer_study(const std::string& setup_path);
std::vector<WrittenTable> tribometer_tables(const TribometerStudy& study, const std::vector<TribometerEstimate>& results);
std::string tribometer_summary(const TribometerStudy& study, const std::vector<TribometerEstimate>& results);

}  // namespace mufric
