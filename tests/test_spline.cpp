// Spline kernel verification: each check against an independent answer — Bernstein polynomials,
// partition of unity, finite differences, exact circles, unchanged geometry after h- and
// p-refinement, recovery of a known spline by fitting, and brute-force dense sampling for the
// closest-point projection on adversarial profiles.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <limits>
#include <random>

#include "common/error.hpp"
#include "common/sanitizers.hpp"
#include "micro/spline/closest_point.hpp"
#include "micro/spline/profile.hpp"
#include "micro/spline/spline_surface.hpp"

namespace mufric::spline {
namespace {

std::vector<SplineBasis> test_bases() {
  return {SplineBasis::open_uniform(1, 4, 0.0, 1.0),
          SplineBasis::open_uniform(3, 5, -1.0, 2.0),
          SplineBasis::open(2, {0, 0, 0, 0.2, 0.2, 0.5, 0.9, 1, 1, 1}),  // a double knot: C0 at 0.2
          SplineBasis::open(4, {0, 0, 0, 0, 0, 0.3, 0.35, 0.8, 1, 1, 1, 1, 1}),
          SplineBasis::periodic_uniform(2, 5, 0.0, 1.0),
          SplineBasis::periodic(3, {0.0, 0.1, 0.15, 0.5, 0.5, 0.7}, 1.0)};
}

// Sum of the basis functions' r-th derivatives at u (all functions, periodic ones summed once).
double derivative_sum(const SplineBasis& b, double u, int r) {
  const auto at = b.locate(u);
  return b.derivatives(at.span, at.u, r).row(r).sum();
}

TEST(SplineBasis, PartitionOfUnityAndNonNegativity) {
  for (const auto& b : test_bases()) {
    for (int s = 0; s <= 200; ++s) {
      const double u = b.lo() + (b.hi() - b.lo()) * s / 200.0;
      const auto at = b.locate(u);
      const Eigen::VectorXd n = b.values(at.span, at.u);
      EXPECT_NEAR(n.sum(), 1.0, 1e-14) << "degree " << b.degree() << " u " << u;
      EXPECT_GE(n.minCoeff(), -1e-15);
      EXPECT_NEAR(derivative_sum(b, u, 1), 0.0, 1e-11);  // Σ N' = 0
    }
  }
}

TEST(SplineBasis, OneSpanIsTheBernsteinBasis) {
  for (int p = 1; p <= 5; ++p) {
    const auto b = SplineBasis::open_uniform(p, 1, 0.0, 1.0);
    for (const double u : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      const auto at = b.locate(u);
      const Eigen::VectorXd n = b.values(at.span, at.u);
      for (int j = 0; j <= p; ++j) {
        const double binomial = std::tgamma(p + 1) / (std::tgamma(j + 1) * std::tgamma(p - j + 1));
        EXPECT_NEAR(n(j), binomial * std::pow(u, j) * std::pow(1 - u, p - j), 1e-14);
      }
    }
  }
}

TEST(SplineBasis, DerivativesMatchFiniteDifferences) {
  for (const auto& b : test_bases()) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 50; ++trial) {
      const double u = b.lo() + (b.hi() - b.lo()) * (0.01 + 0.98 * unit(rng));
      const auto at = b.locate(u);
      const double h = 1e-6 * (b.hi() - b.lo());
      const double lo_knot = b.knot(at.span), hi_knot = b.knot(at.span + 1);
      if (u - h <= lo_knot || u + h >= hi_knot) continue;  // the finite difference must stay in the span
      const Eigen::MatrixXd d = b.derivatives(at.span, u, 2);
      const Eigen::VectorXd plus = b.values(at.span, u + h), minus = b.values(at.span, u - h);
      const Eigen::VectorXd first = (plus - minus) / (2 * h);
      const Eigen::VectorXd second = (plus - 2 * b.values(at.span, u) + minus) / (h * h);
      const double scale = d.row(1).cwiseAbs().maxCoeff() + 1.0;
      EXPECT_LT((d.row(1).transpose() - first).cwiseAbs().maxCoeff(), 1e-7 * scale);
      if (b.degree() >= 2) {
        EXPECT_LT((d.row(2).transpose() - second).cwiseAbs().maxCoeff(), 1e-2 * scale * scale);
      }
    }
  }
}

TEST(SplineBasis, RefusesBadKnotVectors) {
  EXPECT_THROW(SplineBasis::open(2, {0, 0, 1, 0.5, 1, 1}), Error);                 // decreasing
  EXPECT_THROW(SplineBasis::open(2, {0, 0, 0, 1}), Error);                           // too short
  EXPECT_THROW(SplineBasis::open(1, {0, 0, 0.5, 0.5, 0.5, 1, 1}), Error);          // multiplicity 3 > p + 1
  EXPECT_THROW(SplineBasis::periodic(3, {0.0, 0.5}, 1.0), Error);                   // fewer than p + 1 knots
  EXPECT_THROW(SplineBasis::periodic(2, {0.0, 0.5, 1.2}, 1.0), Error);              // knot beyond the period
}

// A full circle of radius r as a closed periodic-knot NURBS (Piegl & Tiller §7.5, nine points in
// the open form; here the open form, which every reader can check by hand).
SplineCurve nurbs_circle(double r) {
  const double s = std::sqrt(0.5);
  const auto basis = SplineBasis::open(2, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1});
  Points2 p(9, 2);
  p << 1, 0, 1, 1, 0, 1, -1, 1, -1, 0, -1, -1, 0, -1, 1, -1, 1, 0;
  Eigen::VectorXd w(9);
  w << 1, s, 1, s, 1, s, 1, s, 1;
  return SplineCurve(basis, r * p, w);
}

TEST(SplineCurve, NurbsCircleIsExactAndItsTangentIsPerpendicular) {
  const SplineCurve c = nurbs_circle(2.0);
  for (int s = 0; s <= 400; ++s) {
    const Points2 d = c.derivatives(s / 400.0, 2);
    EXPECT_NEAR(d.row(0).norm(), 2.0, 1e-14);
    EXPECT_NEAR(d.row(0).dot(d.row(1)), 0.0, 1e-12 * d.row(1).norm());
    // Curvature of a circle is 1/r: |C' × C''| / |C'|³.
    const double cross = d(1, 0) * d(2, 1) - d(1, 1) * d(2, 0);
    EXPECT_NEAR(std::abs(cross) / std::pow(d.row(1).norm(), 3), 0.5, 1e-11);
  }
}

SplineCurve random_profile_curve(int degree, int n, unsigned seed, double period = 10.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Points2 p(n, 2);
  for (int i = 0; i < n; ++i) p.row(i) << period * (i + 0.3 * unit(rng)) / n, unit(rng);
  return SplineCurve(SplineBasis::periodic_uniform(degree, n, 0.0, 1.0), p, {}, Eigen::Vector2d(period, 0.0));
}

TEST(SplineCurve, DerivativesMatchFiniteDifferencesForNurbsAndPeriodicCurves) {
  const std::vector<SplineCurve> curves = {nurbs_circle(1.0), random_profile_curve(3, 12, 1),
                                           random_profile_curve(4, 9, 2)};
  for (const auto& c : curves) {
    for (const double u : {0.061, 0.33, 0.52, 0.97}) {
      const double h = 1e-6;
      const Points2 d = c.derivatives(u, 2);
      const Eigen::Vector2d fd1 = (c.point(u + h) - c.point(u - h)) / (2 * h);
      const Eigen::Vector2d fd2 = (c.derivatives(u + h, 1).row(1) - c.derivatives(u - h, 1).row(1)).transpose() / (2 * h);
      EXPECT_LT((d.row(1).transpose() - fd1).norm(), 1e-7 * (1 + d.row(1).norm()));
      EXPECT_LT((d.row(2).transpose() - fd2).norm(), 1e-6 * (1 + d.row(2).norm()));
    }
  }
}

TEST(SplineCurve, PeriodicCurveRepeatsWithItsShiftAndIsSmoothAcrossTheSeam) {
  const SplineCurve c = random_profile_curve(3, 10, 5);
  for (const double u : {0.0, 0.21, 0.9}) {
    EXPECT_LT((c.point(u + 1.0) - c.point(u) - c.shift()).norm(), 1e-13);
    EXPECT_LT((c.point(u - 2.0) - c.point(u) + 2.0 * c.shift()).norm(), 1e-13);
  }
  // C² across u = 0 for a cubic with simple knots: one-sided values agree.
  const double e = 1e-9;
  const Points2 left = c.derivatives(-e, 2), right = c.derivatives(e, 2);
  EXPECT_LT((left.row(1) - right.row(1)).norm(), 1e-6 * right.row(1).norm());
  EXPECT_LT((left.row(2) - right.row(2)).norm(), 1e-5 * right.row(2).norm());
}

double max_deviation(const SplineCurve& a, const SplineCurve& b, double lo, double hi) {
  double worst = 0.0;
  for (int s = 0; s <= 1000; ++s) {
    const double u = lo + (hi - lo) * s / 1000.0;
    worst = std::max(worst, (a.point(u) - b.point(u)).norm());
  }
  return worst;
}

TEST(SplineCurve, KnotInsertionLeavesTheGeometryUnchanged) {
  const SplineCurve circle = nurbs_circle(1.0);
  const SplineCurve circle_refined = circle.refined({0.1, 0.25, 0.6, 0.6, 0.61});
  EXPECT_EQ(circle_refined.basis().count(), circle.basis().count() + 5);
  EXPECT_LT(max_deviation(circle, circle_refined, 0.0, 1.0), 1e-14);
  for (int degree = 1; degree <= 4; ++degree) {
    const SplineCurve c = random_profile_curve(degree, 8, 10 + degree);
    // Including spans next to the seam, where the insertion wraps around the period.
    // 0.5 is already a knot: for degree ≥ 2 its multiplicity rises to 2 (still C⁰ or better).
    const SplineCurve r = c.refined({0.01, degree >= 2 ? 0.5 : 0.51, 0.98, 0.999, 0.0625});
    EXPECT_EQ(r.basis().count(), 13);
    EXPECT_LT(max_deviation(c, r, -1.0, 2.0), 1e-13) << "degree " << degree;
    EXPECT_LT(max_deviation(c, c.subdivided(3), -1.0, 2.0), 1e-13) << "degree " << degree;
  }
}

TEST(SplineCurve, DegreeElevationLeavesTheGeometryUnchanged) {
  const SplineCurve circle = nurbs_circle(1.0);
  const SplineCurve high = circle.elevated().elevated();
  EXPECT_EQ(high.basis().degree(), 4);
  EXPECT_LT(max_deviation(circle, high, 0.0, 1.0), 1e-13);
  for (int degree = 1; degree <= 3; ++degree) {
    const SplineCurve c = random_profile_curve(degree, 9, 20 + degree);
    const SplineCurve e = c.elevated();
    EXPECT_EQ(e.basis().degree(), degree + 1);
    EXPECT_EQ(e.basis().count(), 18);  // every one of the 9 periodic knots gains one
    EXPECT_LT(max_deviation(c, e, -1.0, 2.0), 1e-12) << "degree " << degree;
  }
}

TEST(ProfileFit, LeastSquaresRecoversAKnownPeriodicSpline) {
  const SplineCurve truth = random_profile_curve(3, 14, 40);
  Points2 samples(300, 2);
  std::vector<double> parameters;
  for (int k = 0; k < 300; ++k) {
    parameters.push_back((k + 0.37) / 300.0);
    samples.row(k) = truth.point(parameters.back()).transpose();
  }
  const SplineCurve fitted = fit_periodic_curve(samples, parameters, truth.basis(), truth.shift());
  EXPECT_LT((fitted.points() - truth.points()).cwiseAbs().maxCoeff(), 1e-11);
  // Too many functions for the data: refused, not silently singular.
  EXPECT_THROW(fit_periodic_curve(samples.topRows(10), {parameters.begin(), parameters.begin() + 10},
                                  truth.basis(), truth.shift()),
               Error);
}

TEST(ProfileFit, ChordLengthFitOfASmoothProfileConvergesWithRefinement) {
  // h(x) = a sin(2πx/L) + b cos(6πx/L): the fit error must fall at least 8× per doubling for a
  // cubic (O(h⁴) would be 16×) and be tiny at 64 control points.
  Profile profile;
  profile.period = 10e-6;
  for (int k = 0; k < 800; ++k) {
    const double x = profile.period * k / 800.0;
    profile.x.push_back(x);
    profile.height.push_back(0.3e-6 * std::sin(2 * std::numbers::pi * x / profile.period) +
                             0.1e-6 * std::cos(6 * std::numbers::pi * x / profile.period));
  }
  double previous = 0.0;
  for (const int n : {16, 32, 64}) {
    const ProfileFit fit = fit_periodic_profile(profile, 3, n);
    if (previous > 0.0) {
      EXPECT_LT(fit.max_error, previous / 8.0) << n << " control points";
    }
    previous = fit.max_error;
    EXPECT_LT((fit.curve.point(1.0) - fit.curve.point(0.0) - Eigen::Vector2d(profile.period, 0.0)).norm(), 1e-18);
  }
  EXPECT_LT(previous, 1e-11);
}

TEST(RoughProfile, HasTheRequestedRoughnessAndIsReproducible) {
  RoughnessSpec spec{.length = 100e-6, .ra = 0.25e-6, .correlation_length = 1e-6, .samples = 4096};
  const Profile a = synthetic_rough_profile(spec), b = synthetic_rough_profile(spec);
  EXPECT_EQ(a.height, b.height);
  spec.seed = 2;
  EXPECT_NE(synthetic_rough_profile(spec).height, a.height);
  const RoughnessFigures f = roughness_figures(a);
  EXPECT_NEAR(f.ra, 0.25e-6, 1e-18);
  // Gaussian heights: Rq/Ra = √(π/2); the measured autocorrelation length is λ within sampling error.
  EXPECT_NEAR(f.rq / f.ra, std::sqrt(std::numbers::pi / 2), 0.08);
  EXPECT_NEAR(f.correlation_length, 1e-6, 0.25e-6);
  EXPECT_GT(f.rz, 4 * f.ra);
  EXPECT_DOUBLE_EQ(a.period, 100e-6);
}

TEST(RoughProfile, CsvWithUnitsIsReadAndBadRowsAreNamed) {
  const auto dir = std::filesystem::temp_directory_path() / ("mufric_profile_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(dir / "good.csv");
    out << "# confocal export\nx[um],height[nm]\n" << std::setprecision(17);
    for (int k = 0; k < 20; ++k) out << 0.5 * k << "," << 100 * std::sin(k) << "\n";
  }
  const Profile p = read_profile_csv((dir / "good.csv").string());
  EXPECT_DOUBLE_EQ(p.x[2], 1e-6);
  EXPECT_NEAR(p.height[1], 100e-9 * std::sin(1.0), 1e-20);
  EXPECT_NEAR(p.period, 10e-6, 1e-18);
  {
    std::ofstream out(dir / "bad.csv");
    out << "x[um],height[um]\n";
    for (int k = 0; k < 12; ++k) out << (k == 7 ? 5.0 : k) << ",0\n";
  }
  try {
    read_profile_csv((dir / "bad.csv").string());
    ADD_FAILURE() << "non-increasing x accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:9"), std::string::npos) << e.what();
  }
  // A length column must carry a length unit: another kind's (height[MPa] reported Ra 3e13 um) or
  // none (read as metres) is refused, naming the column (issue 30).
  for (const std::string header : {"x[um],height[MPa]", "x[um],height", "x,height[um]"}) {
    {
      std::ofstream out(dir / "units.csv");
      out << header << "\n";
      for (int k = 0; k < 12; ++k) out << k << "," << k % 3 << "\n";
    }
    try {
      read_profile_csv((dir / "units.csv").string());
      ADD_FAILURE() << header << " accepted";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_TRUE(m.find("has no unit") != std::string::npos || m.find("expected a length") != std::string::npos) << m;
    }
  }
  std::filesystem::remove_all(dir);
}

// Brute force: the smallest distance over a dense sampling of `periods` periods around x.
struct BruteForce {
  double distance;
  double resolution;  // max |C'| Δu / 2: how far the sampled minimum may lie above the true one
};
BruteForce brute_force(const SplineCurve& c, const Eigen::Vector2d& x, double lo, double hi, int samples) {
  BruteForce b{std::numeric_limits<double>::infinity(), 0.0};
  const double du = (hi - lo) / samples;
  for (int s = 0; s <= samples; ++s) {
    const Points2 d = c.derivatives(lo + du * s, 1);
    b.distance = std::min(b.distance, (d.row(0).transpose() - x).norm());
    b.resolution = std::max(b.resolution, d.row(1).norm() * du / 2);
  }
  return b;
}

// Dense enough that its resolution bound is ~1e-6 of the profile; a fifth of that under the
// sanitizers (10x slower there): the bound follows the sampling, so the test checks the same claim.
#if MUFRIC_ADDRESS_SANITIZER || MUFRIC_THREAD_SANITIZER
constexpr int kBruteForceSamples = 60000;
#else
constexpr int kBruteForceSamples = 300000;
#endif

void expect_matches_brute_force(const SplineCurve& c, const Eigen::Vector2d& x, const std::string& what) {
  const Projection p = project(c, x);
  const BruteForce b = brute_force(c, x, -1.0, 2.0, kBruteForceSamples);
  EXPECT_TRUE(p.converged) << what << ": " << p.reason;
  EXPECT_LE(p.distance, b.distance + 1e-12) << what;  // never worse than dense sampling
  EXPECT_GE(p.distance, b.distance - b.resolution) << what;
  EXPECT_NEAR((p.foot - x).norm(), p.distance, 1e-14);
}

TEST(ClosestPoint, AgreesWithBruteForceOnRoughProfilesOfEveryDegree) {
  for (int degree = 2; degree <= 4; ++degree) {
    RoughnessSpec spec;
    spec.length = 1.0;
    spec.ra = 0.05;
    spec.correlation_length = 0.05;
    spec.samples = 256;
    spec.seed = static_cast<unsigned>(degree);
    const SplineCurve c = fit_periodic_profile(synthetic_rough_profile(spec), degree, 60).curve;
    std::mt19937_64 rng(degree);
    std::uniform_real_distribution<double> ux(-0.2, 1.2), uy(-0.3, 0.4);
    for (int trial = 0; trial < 25; ++trial) {
      const Eigen::Vector2d x(ux(rng), uy(rng));
      expect_matches_brute_force(c, x, "degree " + std::to_string(degree));
      // A search bounded to a window around the answer (as the contact search does) finds it too.
      const Projection global = project(c, x);
      ProjectionOptions window;
      window.window_lo = global.u - 0.07;
      window.window_hi = global.u + 0.05;
      EXPECT_NEAR(project(c, x, window).distance, global.distance, 1e-14);
      // And so does a search seeded from a precomputed table of the curve's samples.
      const ProjectionSeeds seeds(c);
      window.seeds = &seeds;
      const Projection seeded = project(c, x, window);
      EXPECT_NEAR(seeded.distance, global.distance, 1e-14);
      EXPECT_NEAR(seeded.u, project(c, x, ProjectionOptions{.seeds = &seeds}).u, 1e-12);
    }
  }
}

TEST(ClosestPoint, DivergedPointsFailWithAReasonInsteadOfExhaustingMemory) {
  RoughnessSpec spec;
  spec.length = 1.0;
  spec.ra = 0.05;
  spec.correlation_length = 0.05;
  spec.samples = 128;
  const SplineCurve c = fit_periodic_profile(synthetic_rough_profile(spec), 3, 30).curve;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Eigen::Vector2d& x : {Eigen::Vector2d(nan, 0.0), Eigen::Vector2d(0.5, 1e300), Eigen::Vector2d(1e200, 0.0)}) {
    const Projection p = project(c, x);
    EXPECT_FALSE(p.converged);
    EXPECT_FALSE(p.reason.empty());
  }
  EXPECT_NE(project(c, Eigen::Vector2d(nan, 0.0)).reason.find("diverged"), std::string::npos);
  EXPECT_NE(project(c, Eigen::Vector2d(1e200, 0.0)).reason.find("diverged"), std::string::npos);
  // A window spanning a million periods (what a contact search computes for a far-away point).
  ProjectionOptions window;
  window.window_lo = -1e6;
  window.window_hi = 1e6;
  const Projection p = project(c, Eigen::Vector2d(0.5, 0.0), window);
  EXPECT_FALSE(p.converged);
  EXPECT_NE(p.reason.find("periods"), std::string::npos) << p.reason;
}

// Points on or a picometre off a profile 20 µm from the origin, in SI units (the seam of a 20 µm
// contact cell): f = C′·(C − x) is known there only to eps × 20 µm × |C′|, above the relative
// tolerance alone, and the projection never converged (15 of 16 draws of a 20 µm cell stopped).
TEST(ClosestPoint, ConvergesOnTheCurveFarFromTheOrigin) {
  const RoughnessSpec spec{.length = 20e-6, .ra = 0.3e-6, .correlation_length = 1e-6, .samples = 1024, .seed = 3};
  const SplineCurve c = fit_periodic_profile(synthetic_rough_profile(spec), 3, 128).curve;
  long long not_converged = 0;
  for (int i = 0; i <= 200; ++i) {
    const double u = 0.9 + 0.2 * i / 200.0;  // across the seam at u = 1 (x = 20 µm)
    const Points2 d = c.derivatives(u, 1);
    const Eigen::Vector2d normal = Eigen::Vector2d(-d(1, 1), d(1, 0)).normalized();
    for (const double offset : {0.0, 1e-12, -1e-12}) {
      const Eigen::Vector2d x = d.row(0).transpose() + offset * normal;
      const Projection p = project(c, x);
      not_converged += !p.converged;
      EXPECT_LE(p.distance, std::abs(offset) + 1e-15) << u << ": " << p.reason;
    }
  }
  EXPECT_EQ(not_converged, 0);
}

TEST(ClosestPoint, AdversarialProfiles) {
  // Sharp peaks: a cubic through a spiky control polygon.
  Points2 spikes(12, 2);
  for (int i = 0; i < 12; ++i) spikes.row(i) << i / 12.0, (i % 3 == 1) ? 0.6 : 0.0;
  const SplineCurve sharp(SplineBasis::periodic_uniform(3, 12, 0.0, 1.0), spikes, {}, Eigen::Vector2d(1.0, 0.0));
  for (const double x : {0.05, 0.083, 0.1, 0.25, 0.33, 0.5}) {
    for (const double y : {0.35, 0.2, -0.1, 0.8}) expect_matches_brute_force(sharp, {x, y}, "sharp peaks");
  }
  // A near-cusp: three almost coincident control points of a cubic (C' nearly vanishes there).
  Points2 cusp(8, 2);
  cusp << 0.0, 0.0, 0.2, 0.1, 0.4, 0.5, 0.4 + 1e-9, 0.5, 0.4 + 2e-9, 0.5, 0.6, 0.1, 0.8, 0.0, 0.9, -0.05;
  const SplineCurve near_cusp(SplineBasis::periodic_uniform(3, 8, 0.0, 1.0), cusp, {}, Eigen::Vector2d(1.0, 0.0));
  for (const double x : {0.3, 0.4, 0.45, 0.5}) {
    for (const double y : {0.45, 0.6, 0.3}) expect_matches_brute_force(near_cusp, {x, y}, "near-cusp");
  }
  // Equidistant from two identical peaks: a point above the valley on the symmetry axis.
  Points2 twin(8, 2);
  twin << 0.0, 0.0, 0.125, 0.0, 0.25, 0.8, 0.375, 0.0, 0.5, 0.0, 0.625, 0.0, 0.75, 0.8, 0.875, 0.0;
  const SplineCurve twins(SplineBasis::periodic_uniform(2, 8, 0.0, 1.0), twin, {}, Eigen::Vector2d(1.0, 0.0));
  for (const double y : {0.3, 0.6, 1.0}) {
    expect_matches_brute_force(twins, {0.5, y}, "equidistant");
    const Projection left = project(twins, {0.5 - 1e-12, y}), right = project(twins, {0.5 + 1e-12, y});
    EXPECT_NEAR(left.distance, right.distance, 1e-11);
  }
}

TEST(SplineSurface, ExtrudedPatchRefinesAndElevatesWithoutChangingShape) {
  const SplineCurve top = random_profile_curve(3, 10, 77);
  const SplineSurface s = SplineSurface::extruded(top, -3.0, 2, 3);
  EXPECT_EQ(s.v_basis().degree(), 2);
  EXPECT_LT(max_deviation(s.top(), top, -1.0, 2.0), 1e-13);
  const SplineSurface fine = s.subdivided(2, 2).elevated_u().elevated_v();
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double u = 3 * unit(rng) - 1, v = unit(rng);
    EXPECT_LT((s.point(u, v) - fine.point(u, v)).norm(), 1e-12);
    EXPECT_LT((s.point(u + 1.0, v) - s.point(u, v) - s.shift()).norm(), 1e-12);
    const double h = 1e-6;
    Eigen::Matrix2d fd;
    fd.col(0) = (s.point(u + h, v) - s.point(u - h, v)) / (2 * h);
    fd.col(1) = (s.point(u, std::min(v + h, 1.0)) - s.point(u, std::max(v - h, 0.0))) /
                (std::min(v + h, 1.0) - std::max(v - h, 0.0));
    EXPECT_LT((s.jacobian(u, v) - fd).norm(), 1e-6 * s.jacobian(u, v).norm());
  }
  EXPECT_NEAR(s.point(0.3, 0.0).y(), -3.0, 1e-14);
}

}  // namespace
}  // namespace mufric::spline
