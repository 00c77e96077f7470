// Measured tests to calibration rows (surrogate/reduction): NumPy's stream against NumPy's own
// numbers, the orthogonal-cut analysis against closed forms on forces made from a known friction
// angle, and against the Ti6Al4V tables the analysis' first (Python) form wrote.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/numpy_random.hpp"
#include "surrogate/reduction/orthogonal_cut_files.hpp"
#include "surrogate/reduction/orthogonal_cutting.hpp"
#include "surrogate/reduction/tribometer.hpp"
#include "surrogate/calibration/measurements.hpp"
#include "error_text.hpp"
#include "temp_path.hpp"

namespace mufric {
namespace {

const std::string kTi6Al4V = MUFRIC_SOURCE_DIR "/data/cirp2022_ti6al4v_tin/";

TEST(NumpyRandom, GivesNumpysOwnDraws) {
  // numpy 1.24.2: g = numpy.random.default_rng(7); g.bit_generator.random_raw(2);
  // g.standard_normal(3); g.uniform(2.0, 5.0)
  NumpyRandom rng(7);
  EXPECT_EQ(rng.next_uint64(), 11530976094092348043ull);
  EXPECT_EQ(rng.next_uint64(), 16550673365885938325ull);
  // The ziggurat's tables are built here by Marsaglia & Tsang's recursion, not copied: they agree
  // with NumPy's to about 1e-14, and every accept/reject decision with them.
  for (double expected : {-0.2741378553622176, -0.8905918387572742, -0.45467078517172255})
    EXPECT_NEAR(rng.standard_normal(), expected, 1e-13 * std::abs(expected));
  EXPECT_DOUBLE_EQ(rng.uniform(2.0, 5.0), 4.620660336188786);
}

TEST(NumpyRandom, NormalsHaveUnitVarianceAndAnUntruncatedTail) {
  NumpyRandom rng(2026);
  constexpr int kDraws = 400000;
  double sum = 0, squares = 0;
  int beyond_tail_start = 0;  // past the ziggurat's base layer r = 3.654: P(|z| > r) = 2.58e-4
  for (int i = 0; i < kDraws; ++i) {
    const double z = rng.standard_normal();
    sum += z;
    squares += z * z;
    if (std::abs(z) > 3.6541528853610088) ++beyond_tail_start;
  }
  EXPECT_NEAR(sum / kDraws, 0.0, 5.0 / std::sqrt(kDraws));
  EXPECT_NEAR(squares / kDraws, 1.0, 5.0 * std::sqrt(2.0 / kDraws));
  const double expected = kDraws * std::erfc(3.6541528853610088 / std::sqrt(2.0));
  EXPECT_NEAR(beyond_tail_start, expected, 5.0 * std::sqrt(expected));
}

OrthogonalCutSetup titanium_like_setup() {
  OrthogonalCutSetup setup;
  setup.rake_angle = 15.0 * std::numbers::pi / 180.0;
  setup.cut_width = 1e-3;
  setup.density = 4430.0;
  setup.conductivity = {7.0, 7.0};
  setup.specific_heat = {560.0, 560.0};
  setup.room_temperature = 293.0;
  setup.draws = 64;
  setup.seed = 1;
  return setup;
}

// Chip-forming forces whose resultant makes the friction angle β with the rake face's normal:
// Fc = R cos(β − γ), Ff = R sin(β − γ) per unit h (Merchant's force circle), plus edge forces that do
// not grow with h; tiny errors, so every draw is the closed form.
std::vector<OrthogonalCut> merchant_cuts(double gamma, double beta, double edge_c, double edge_f, double chip_ratio) {
  constexpr double kNewtonsPerMetreOfH = 1.7e6;  // 1.7 N per µm of h, 1 mm wide
  std::vector<OrthogonalCut> cuts;
  int line = 2;
  for (double speed : {5.0 / 60.0, 40.0 / 60.0})
    for (double h : {40e-6, 60e-6, 80e-6}) {
      OrthogonalCut cut;
      cut.cutting_speed = speed;
      cut.uncut_chip_thickness = h;
      cut.cutting_force = {edge_c + kNewtonsPerMetreOfH * h * std::cos(beta - gamma), 1e-6};
      cut.feed_force = {edge_f + kNewtonsPerMetreOfH * h * std::sin(beta - gamma), 1e-6};
      cut.chip_ratio = {chip_ratio, 1e-9};
      cut.row_name = "made line " + std::to_string(line++);
      cuts.push_back(cut);
    }
  return cuts;
}

TEST(OrthogonalCuts, MerchantsFrictionTheEdgeForcesAndOxleysContactLengthComeBack) {
  const OrthogonalCutSetup setup = titanium_like_setup();
  const double gamma = setup.rake_angle, beta = 24.0 * std::numbers::pi / 180.0, ratio = 1.5;
  const auto results = rake_face_from_orthogonal_cuts(merchant_cuts(gamma, beta, 30.0, 35.0, ratio), setup);
  ASSERT_EQ(results.size(), 2u);
  for (const auto& r : results) {
    EXPECT_NEAR(r.mu.mean, std::tan(beta), 1e-6);
    EXPECT_NEAR(r.edge_cutting_force.mean, 30.0, 1e-4);
    EXPECT_NEAR(r.edge_feed_force.mean, 35.0, 1e-4);
    // tan φ = cos γ / (λh − sin γ); Oxley's l_c/h = sin θ / (cos β sin φ) (1 + C n_eq / (3 tan θ)), θ = β + φ − γ.
    const double phi = std::atan(std::cos(gamma) / (ratio - std::sin(gamma)));
    EXPECT_NEAR(r.shear_angle.mean, phi, 1e-8);
    const double theta = beta + phi - gamma;
    const double c_neq = std::max(0.0, 1.0 + std::numbers::pi / 2.0 - 2.0 * phi - std::tan(theta));
    const double contact_per_h = std::sin(theta) / (std::cos(beta) * std::sin(phi)) * (1.0 + c_neq / (3.0 * std::tan(theta)));
    EXPECT_NEAR(r.contact_length_per_h.mean, contact_per_h, 1e-6);
    // The normal force on the rake face over the contact area: R cos β h / (l_c).
    const double normal_per_h = 1.7e6 * std::cos(beta) / 1e-3;
    EXPECT_NEAR(r.contact_pressure.mean / (normal_per_h / contact_per_h), 1.0, 1e-6);
    EXPECT_NEAR(r.sliding_velocity.mean / (r.cutting_speed / ratio), 1.0, 1e-9);  // the ratio's SE is 1e-9
    EXPECT_EQ(r.thicknesses.size(), 3u);
    EXPECT_DOUBLE_EQ(r.birge_feed, 1.0);
  }
}

TEST(OrthogonalCuts, ThreeMeansOffTheirLineWidenTheSlopeByTheBirgeRatio) {
  OrthogonalCutSetup setup = titanium_like_setup();
  auto cuts = merchant_cuts(setup.rake_angle, 0.4, 30.0, 35.0, 1.5);
  for (auto& cut : cuts) cut.feed_force.standard_error = 1.0;
  cuts[1].feed_force.mean += 6.0;  // the middle thickness of 5 m/min: residuals 2, −4, 2 (in units of 1 N)
  const auto results = rake_face_from_orthogonal_cuts(cuts, setup);
  // χ² = (2² + 4² + 2²)/1 on one degree of freedom.
  EXPECT_NEAR(results[0].birge_feed, std::sqrt(24.0), 1e-9);
  EXPECT_DOUBLE_EQ(results[1].birge_feed, 1.0);
}

TEST(OrthogonalCuts, RefusesWhatCannotGiveARakeFace) {
  const OrthogonalCutSetup setup = titanium_like_setup();
  auto cuts = merchant_cuts(setup.rake_angle, 0.4, 30.0, 35.0, 1.5);
  auto one_thickness = cuts;
  one_thickness.erase(one_thickness.begin() + 1, one_thickness.begin() + 3);
  try {
    rake_face_from_orthogonal_cuts(one_thickness, setup);
    FAIL() << "one thickness accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("made line 2: the only uncut chip thickness at 5 m/min"), std::string::npos) << e.what();
  }
  auto no_scatter = cuts;
  no_scatter[4].chip_ratio.standard_error = 0.0;
  EXPECT_THROW(rake_face_from_orthogonal_cuts(no_scatter, setup), Error);
}

std::vector<std::string> cells(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::stringstream row(line);
    std::string cell;
    while (std::getline(row, cell, ',')) out.push_back(cell);
  }
  return out;
}

TEST(OrthogonalCuts, GivesTheTi6Al4VTablesTheirFirstFormWrote) {
  // data/cirp2022_ti6al4v_tin/rake_face_mu_0deg.csv and rake_face_analysis.csv were written by the
  // analysis' Python form (rake_face.py, NumPy's stream, 20000 draws, seed 2026) before this library.
  const OrthogonalCutStudy study = read_orthogonal_cut_study(kTi6Al4V + "orthogonal_cuts.json");
  EXPECT_EQ(study.cuts.size(), 36u);
  const auto tables = orthogonal_cut_tables(study, rake_face_from_orthogonal_cuts(study.cuts, study.setup));
  ASSERT_EQ(tables.size(), 2u);
  ASSERT_EQ(tables[1].file_name, "rake_face_mu_0deg.csv");
  EXPECT_EQ(tables[1].text, read_whole_file(kTi6Al4V + "rake_face_mu_0deg.csv").value());
  ASSERT_EQ(tables[0].file_name, "rake_face_analysis.csv");
  const auto ours = cells(tables[0].text), theirs = cells(read_whole_file(kTi6Al4V + "rake_face_analysis.csv").value());
  ASSERT_EQ(ours.size(), theirs.size());
  int rounding_noise = 0;
  for (size_t i = 0; i < ours.size(); ++i) {
    if (ours[i] == theirs[i]) continue;
    // NumPy's SD of a constant column (a Birge scale repeated over the draws) is its summation's
    // rounding, 8.9e-16 once; ours is 0.
    EXPECT_EQ(ours[i], "0") << "cell " << i << ": " << ours[i] << " against " << theirs[i];
    EXPECT_LT(std::abs(std::stod(theirs[i])), 1e-12) << "cell " << i;
    ++rounding_noise;
  }
  EXPECT_LE(rounding_noise, 1);
}

TEST(OrthogonalCuts, ASetupsErrorsNameTheField) {
  const std::string path = test::temp_path("cuts_setup.json");
  auto setup_with = [&](const std::string& body) {
    std::ofstream(path) << "{\"tests\": \"" << kTi6Al4V << "cutting_tests.csv\", " << body << "}";
    try {
      read_orthogonal_cut_study(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string good_units = R"("rake_angle": "15deg", "cut_width": "1mm", "room_temperature": "293K", )";
  EXPECT_NE(setup_with(R"("cut_width": "1mm")").find("no 'rake_angle'"), std::string::npos);
  EXPECT_NE(setup_with(R"("rake_angle": "15", "cut_width": "1mm")").find("'rake_angle'"), std::string::npos);
  EXPECT_NE(setup_with(good_units + R"("density_kg_per_m3": 4430, "conductivity_W_per_m_K": [6.3], "specific_heat_J_per_kg_K": 560)")
                .find("'conductivity_W_per_m_K' must be a number or a range"),
            std::string::npos);
  EXPECT_NE(setup_with(good_units + R"("density_kg_per_m3": 4430, "conductivity_W_per_m_K": 7, "specific_heat_J_per_kg_K": 560, "uncertainty": "3sd")")
                .find("'uncertainty' is '3sd'"),
            std::string::npos);
  // The file's own column names are not the defaults: the missing column is named with those present
  // and the setup's "columns" pointed to.
  EXPECT_NE(setup_with(good_units + R"("density_kg_per_m3": 4430, "conductivity_W_per_m_K": 7, "specific_heat_J_per_kg_K": 560, "repeats": 3)")
                .find("no column 'chip_ratio' (columns: inclination_angle, cutting_speed"),
            std::string::npos);
}

}  // namespace
}  // namespace mufric

namespace mufric {
namespace {

// The groove's frontal area by quadrature (Simpson): depth √(R² − y²) − √(R² − a²) across |y| ≤ a;
// over the front half-circle's area π a²/2, the load's, it is the ploughing coefficient.
double brute_force_ploughing(double a_over_r) {
  constexpr int kIntervals = 20000;
  const double r = 1.0, a = a_over_r, floor = std::sqrt(r * r - a * a);
  double area = 0.0;
  for (int k = 0; k <= kIntervals; ++k) {
    const double y = -a + 2.0 * a * k / kIntervals;
    const double weight = (k == 0 || k == kIntervals) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    area += weight * (std::sqrt(std::max(0.0, r * r - y * y)) - floor);
  }
  area *= 2.0 * a / kIntervals / 3.0;
  return area / (std::numbers::pi * a * a / 2.0);
}

TEST(Tribometer, GoddardWilmansPloughingIsTheGroovesFrontalAreaOverTheLoadsHalfCircle) {
  for (double x : {0.01, 0.05, 0.2, 0.5, 0.9, 1.0}) EXPECT_NEAR(sphere_ploughing_coefficient(x), brute_force_ploughing(x), 1e-6) << x;
  EXPECT_NEAR(sphere_ploughing_coefficient(1e-3) / 1e-3, 4.0 / (3.0 * std::numbers::pi), 1e-5);  // shallow: 4a/(3πR)
  EXPECT_NEAR(sphere_ploughing_coefficient(1.0), 1.0, 1e-12);                                    // to the equator
  EXPECT_THROW(sphere_ploughing_coefficient(1.2), Error);
}

TribometerTest pin_test(double force, double mu_apparent, double pressure, int line) {
  TribometerTest t;
  t.sliding_velocity = 1.0;
  t.normal_force = force;
  t.mu_apparent = {mu_apparent, 0.01};
  t.contact_pressure = pressure;
  t.row_name = "pins.csv line " + std::to_string(line);
  return t;
}

TEST(Tribometer, TheInterfacesFrictionComesBackFromApparentFrictionMadeOfItAndThePinsPloughing) {
  TribometerSetup setup;
  setup.pin_radius = 4.5e-3;
  setup.draws = 4000;
  const double pressure = 3e9, adhesive = 0.2;
  std::vector<TribometerTest> tests;
  for (double force : {100.0, 1000.0, 4000.0}) {
    const double a = std::sqrt(2.0 * force / (std::numbers::pi * pressure));
    tests.push_back(pin_test(force, adhesive + sphere_ploughing_coefficient(a / setup.pin_radius), pressure, 2 + static_cast<int>(tests.size())));
  }
  const auto results = friction_from_tribometer(tests, setup);
  ASSERT_EQ(results.size(), 3u);
  for (const auto& r : results) {
    EXPECT_NEAR(r.mu.mean, adhesive, 5.0 * 0.01 / std::sqrt(4000.0));
    EXPECT_NEAR(r.mu.sd, 0.01, 0.001);
    EXPECT_DOUBLE_EQ(r.contact_pressure.mean, pressure);
  }
  EXPECT_LT(results[0].mu_ploughing.mean, results[2].mu_ploughing.mean);  // more load, deeper groove
  setup.ploughing = PloughingCorrection::none;
  EXPECT_NEAR(friction_from_tribometer(tests, setup)[2].mu.mean, tests[2].mu_apparent.mean, 0.001);
}

TEST(Tribometer, RefusesAContactWiderThanThePinAndPloughingThatTakesAllTheFriction) {
  TribometerSetup setup;
  setup.pin_radius = 1e-4;
  EXPECT_NE(test::error_of([&] { friction_from_tribometer({pin_test(1000.0, 0.3, 1e9, 4)}, setup); }).find("pins.csv line 4: the contact's radius"),
            std::string::npos);
  setup.pin_radius = 1e-3;
  EXPECT_NE(test::error_of([&] { friction_from_tribometer({pin_test(1000.0, 0.01, 1e9, 5)}, setup); }).find("takes all of the apparent friction"),
            std::string::npos);
}

TEST(Tribometer, ItsCalibrationRowsAreWhatCalibrateReads) {
  const std::string folder = test::temp_path("tribometer");
  std::filesystem::create_directories(folder);
  std::ofstream(folder + "/pins.csv") << "# a made-up test log\nsliding_velocity[m/s],normal_force[N],mu,mu_sd,temperature[C],notes\n"
                                         "0.5,1000,0.42,0.02,350,\"dry, first run\"\n2.0,1000,0.31,0.03,520,dry\n";
  std::ofstream(folder + "/pins.json") << R"({"tests": "pins.csv", "pin_radius": "4.5mm", "flow_pressure": ["2.5GPa", "3.5GPa"],
      "repeats": 3, "columns": {"temperature": "temperature"}, "provenance": ["made up for a test"]})";
  const TribometerStudy study = read_tribometer_study(folder + "/pins.json");
  const auto tables = tribometer_tables(study, friction_from_tribometer(study.tests, study.setup));
  ASSERT_EQ(tables.size(), 2u);
  write_file_atomically(folder + "/" + tables[1].file_name, tables[1].text);
  const Measurements rows = read_measurements(folder + "/" + tables[1].file_name);
  ASSERT_EQ(rows.rows(), 2);
  EXPECT_EQ(rows.condition_names, (std::vector<std::string>{"contact_pressure", "sliding_velocity", "temperature"}));
  EXPECT_NEAR(rows.conditions(1, 1), 2.0, 1e-6);
  EXPECT_NEAR(rows.conditions(0, 2), 350.0 + 273.15, 1e-6);
  EXPECT_NEAR(rows.conditions(0, 0), 3e9, 0.02e9);                 // the flow pressure's middle
  EXPECT_NEAR(rows.condition_sd(0, 0), 1e9 / std::sqrt(12.0), 0.02e9);  // uniform over 2.5-3.5 GPa
  EXPECT_LT(rows.mu(0), 0.42);                                     // the ploughing taken out
  EXPECT_NE(tables[1].text.find("# made up for a test"), std::string::npos);
}

}  // namespace
}  // namespace mufric
