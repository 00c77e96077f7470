// Seed 001 laws against hand computation from its tables and Listing 1; the MLR fitter against
// known coefficients and an independently computed R².
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include "common/error.hpp"
#include "surrogate/laws/empirical_laws.hpp"

namespace mufric {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The law's own formula, also outside seed 001's box (raw extrapolation: Listing 1's clamp is the law's).
double mu_at(const FrictionModel& law, double p_mpa, double v_m_min, double angle_deg) {
  QueryBatch x(1, 3);
  x << p_mpa * 1e6, v_m_min / 60.0, angle_deg * kDeg;
  EvaluationRequest raw;
  raw.extrapolation = Extrapolation::raw;
  return law.evaluate(x, raw).mu(0);
}

TEST(EmpiricalLaws, Listing1At90DegreesFromTable2) {
  const MlrLaw law = MlrLaw::seed001_table2();
  for (const auto& [p, v] : {std::pair{50.0, 5.0}, std::pair{150.0, 1.0}, std::pair{10.0, 15.0}, std::pair{190.0, 12.0}}) {
    // Listing 1: MA = 0.121109 + 0.0130631*ve − 0.000366846*pr, clamped to [MAmin, MAmax]
    // (Table 2 rounds the pressure coefficient to −0.0003668, which the library uses).
    const double ma = std::clamp(0.121109 + 0.0130631 * v - 0.0003668 * p, 0.093755565, 0.322395506);
    EXPECT_NEAR(mu_at(law, p, v, 90.0), ma, 1e-12) << p << " MPa, " << v << " m/min";
  }
}

TEST(EmpiricalLaws, Table4AtEveryTabulatedAngle) {
  const MlrLaw law = MlrLaw::seed001_table4();
  const double table[8][4] = {{0, 0.052488, 0.006025, 0.0003908},   {22.5, 0.197959, -0.001155, -0.000634},
                              {45, 0.240492, -0.005277, -0.000341}, {67.5, 0.18297, 0.007671, -0.000392},
                              {90, 0.149911, 0.013133, -0.000753},  {112.5, 0.081576, -0.001422, 0.0008751},
                              {135, 0.156666, 0.014112, -0.000684}, {157.5, 0.075583, 0.000894, 0.000419}};
  for (const auto& row : table) {
    const double expected = std::clamp(row[1] + row[2] * 8.0 + row[3] * 120.0, 0.093755565, 0.322395506);
    EXPECT_NEAR(mu_at(law, 120.0, 8.0, row[0]), expected, 1e-12) << row[0] << " deg";
  }
}

TEST(EmpiricalLaws, InterpolatesBetweenAnglesAndWrapsAt180Degrees) {
  const MlrLaw law = MlrLaw::seed001_table4();
  const double a = mu_at(law, 100, 10, 45.0), b = mu_at(law, 100, 10, 67.5);
  EXPECT_NEAR(mu_at(law, 100, 10, 50.625), 0.75 * a + 0.25 * b, 1e-12);
  const double last = mu_at(law, 100, 10, 157.5), first = mu_at(law, 100, 10, 0.0);
  EXPECT_NEAR(mu_at(law, 100, 10, 168.75), 0.5 * last + 0.5 * first, 1e-12);
  EXPECT_NEAR(mu_at(law, 100, 10, 180.0), first, 1e-12);
  EXPECT_NEAR(mu_at(law, 100, 10, -22.5), mu_at(law, 100, 10, 157.5), 1e-12);
}

TEST(EmpiricalLaws, ClampHoldsOutsideTheLinearRange) {
  const MlrLaw law = MlrLaw::seed001_table2();
  EXPECT_DOUBLE_EQ(mu_at(law, 1000.0, 1.0, 90.0), 0.093755565);  // large p drives μ below MAmin
  EXPECT_DOUBLE_EQ(mu_at(law, 0.0, 200.0, 90.0), 0.322395506);   // large v drives μ above MAmax
}

TEST(EmpiricalLaws, GradientMatchesFiniteDifferences) {
  const MlrLaw law = MlrLaw::seed001_table4();
  QueryBatch x(1, 3);
  x << 90e6, 7.0 / 60.0, 80.0 * kDeg;
  const Evaluation e = law.evaluate(x, {.gradient = true});
  for (Eigen::Index c = 0; c < 3; ++c) {
    const double h = std::abs(x(0, c)) * 1e-6;
    QueryBatch plus = x, minus = x;
    plus(0, c) += h;
    minus(0, c) -= h;
    const double fd = (law.evaluate(plus, {}).mu(0) - law.evaluate(minus, {}).mu(0)) / (2 * h);
    EXPECT_NEAR(e.gradient(0, c), fd, 1e-6 * std::abs(fd) + 1e-15);
  }
}

TEST(EmpiricalLaws, CoulombIsConstantWithZeroGradientAndZeroWidthInterval) {
  const CoulombLaw law(0.25);
  QueryBatch x(2, 3);
  x << 500e6, 1.0, 600.0, 900e6, 2.0, 900.0;
  const Evaluation e = law.evaluate(x, {.std = true, .ci_level = 0.95, .gradient = true});
  EXPECT_TRUE((e.mu.array() == 0.25).all());
  EXPECT_TRUE((e.hi - e.lo).isZero());
  EXPECT_TRUE(e.gradient.isZero());
}

std::string write_measurements(const std::string& name, double noise, unsigned seed, int per_angle) {
  const auto path = (std::filesystem::temp_directory_path() / ("mufric_" + std::to_string(::getpid()) + name)).string();
  std::ofstream out(path);
  out.precision(17);
  out << "# synthetic tribometer data\nfibre_angle[deg],contact_pressure[MPa],sliding_velocity[m/min],mu\n";
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> p(20, 200), v(1, 15);
  std::normal_distribution<double> e(0.0, noise);
  const double laws[2][4] = {{0.0, 0.2, 0.004, -0.0003}, {90.0, 0.12, 0.013, -0.0004}};
  for (const auto& law : laws) {
    for (int i = 0; i < per_angle; ++i) {
      const double pi = p(rng), vi = v(rng);
      out << law[0] << "," << pi << "," << vi << "," << law[1] + law[2] * vi + law[3] * pi + (noise > 0 ? e(rng) : 0.0) << "\n";
    }
  }
  return path;
}

TEST(MlrFit, RecoversExactCoefficients) {
  const std::string path = write_measurements("exact.csv", 0.0, 1, 12);
  MlrFitReport report;
  const MlrLaw law = fit_mlr_law(path, &report);
  ASSERT_EQ(law.rows().size(), 2u);
  EXPECT_NEAR(law.rows()[1].beta0, 0.12, 1e-12);
  EXPECT_NEAR(law.rows()[1].beta1_per_m_min, 0.013, 1e-12);
  EXPECT_NEAR(law.rows()[1].beta2_per_mpa, -0.0004, 1e-14);
  EXPECT_NEAR(report.angles[0].r_squared, 1.0, 1e-12);
  std::filesystem::remove(path);
}

TEST(MlrFit, RSquaredMatchesIndependentComputation) {
  const std::string path = write_measurements("noisy.csv", 0.01, 3, 40);
  MlrFitReport report;
  const MlrLaw law = fit_mlr_law(path, &report);
  // Recompute R² at 90° from the CSV with the fitted coefficients: 1 − SSres/SStot.
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::getline(in, line);
  std::vector<double> residual, observed;
  const MlrRow& row = law.rows()[1];
  while (std::getline(in, line)) {
    double a, p, v, mu;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &a, &p, &v, &mu), 4);
    if (a != 90.0) continue;
    observed.push_back(mu);
    residual.push_back(mu - (row.beta0 + row.beta1_per_m_min * v + row.beta2_per_mpa * p));
  }
  double mean = 0;
  for (double o : observed) mean += o / static_cast<double>(observed.size());
  double ss_res = 0, ss_tot = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    ss_res += residual[i] * residual[i];
    ss_tot += (observed[i] - mean) * (observed[i] - mean);
  }
  EXPECT_NEAR(report.angles[1].r_squared, 1.0 - ss_res / ss_tot, 1e-10);
  EXPECT_LT(report.angles[1].r_squared, 1.0);
  EXPECT_NEAR(row.beta1_per_m_min, 0.013, 0.002);
  std::filesystem::remove(path);
}

TEST(MlrFit, TooFewMeasurementsAtAnAngleAreNamed) {
  const std::string path = write_measurements("few.csv", 0.0, 1, 2);
  try {
    fit_mlr_law(path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fibre angle 0.000000 deg"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace mufric
