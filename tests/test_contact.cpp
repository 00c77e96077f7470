// Mortar penalty contact with a rigid tool: the contact patch test, the exact linearisation against
// finite differences, and Hertz's line contact of an elastic cylinder on a rigid flat.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "micro/contact/mortar_contact.hpp"
#include "micro/spline/profile.hpp"
#include "solid_test_support.hpp"

namespace mufric::contact {
namespace {

using spline::Points2;
using spline::SplineBasis;
using spline::SplineCurve;
using spline::SplineSurface;

// A flat periodic tool at height y over the period [0, L], control points spaced unevenly so that
// its parameterisation matches nothing on the chip.
SplineCurve flat_tool(double y, double period, int points, unsigned seed) {
  Points2 p(points, 2);
  for (int i = 0; i < points; ++i) {
    const double jitter = 0.3 * std::sin(1.7 * (i + seed));
    p.row(i) << period * (i + jitter) / points, y;
  }
  return SplineCurve(SplineBasis::periodic_uniform(3, points, 0, 1), p, {}, Eigen::Vector2d(period, 0));
}

SplineCurve flat_chip_surface(double y, double period, int spans) {
  Points2 p(spans, 2);
  for (int i = 0; i < spans; ++i) p.row(i) << period * i / spans, y;
  return SplineCurve(SplineBasis::periodic_uniform(2, spans, 0, 1), p, {}, Eigen::Vector2d(period, 0));
}

TEST(MortarContact, PatchTestTransmitsUniformPressureAndNoShear) {
  const double period = 1.0, height = 0.5, pressure = 1e-3, penalty = 1e3;
  solid::SolidProblem problem(solid::IgaSpace(SplineSurface::extruded(flat_chip_surface(height, period, 7), 0.0, 2, 3)),
                              std::make_shared<solid::LinearElastic>(1.0, 0.3, 1.0));
  // The tool starts 1e-6 inside the chip: contact is active from the first iteration.
  auto contact = std::make_shared<MortarContact>(problem.space(), RigidTool{flat_tool(height - 1e-6, period, 11, 2)},
                                                 penalty);
  problem.add_interaction(contact);
  problem.fix_side(numerics::Side::bottom, 0);
  problem.add_load({numerics::Side::bottom, Eigen::Vector2d::Zero(), pressure, {}});
  const Eigen::VectorXd u = solid::test::solve_static(problem);
  const ContactState s = contact->state(u);
  for (size_t q = 0; q < s.point_pressure.size(); ++q) {
    EXPECT_NEAR(s.point_pressure[q], pressure, 1e-9 * pressure) << "x " << s.point_x[q];
    EXPECT_NEAR(s.point_normal[q].x(), 0.0, 1e-12);
  }
  EXPECT_NEAR(s.force.x(), 0.0, 1e-12 * pressure);
  EXPECT_NEAR(s.force.y(), -pressure * period, 1e-9 * pressure);
  EXPECT_NEAR(s.contact_length, period, 1e-12);
}

TEST(MortarContact, TangentIsTheExactLinearisationOnARoughTool) {
  spline::RoughnessSpec spec;
  spec.length = 1.0;
  spec.ra = 0.02;
  spec.correlation_length = 0.1;
  spec.samples = 256;
  const SplineCurve chip_surface = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 2, 24).curve;
  spec.seed = 9;
  SplineCurve tool_surface = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 3, 30).curve;
  // Lower the tool into the chip's peaks: part of the surface in contact, part not.
  Points2 lowered = tool_surface.points();
  lowered.col(1).array() += 0.03;
  tool_surface = SplineCurve(tool_surface.basis(), lowered, {}, tool_surface.shift());
  solid::SolidProblem problem(solid::IgaSpace(SplineSurface::extruded(chip_surface, -0.5, 2, 3)),
                              std::make_shared<solid::LinearElastic>(1.0, 0.3, 1.0));
  auto contact = std::make_shared<MortarContact>(problem.space(), RigidTool{tool_surface}, 50.0);
  problem.add_interaction(contact);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd u(problem.dof_count());
  for (auto& x : u) x = 2e-3 * unit(rng);
  const ContactState s = contact->state(u);
  EXPECT_GT(s.contact_length, 0.05);
  EXPECT_LT(s.contact_length, 0.95 * s.surface_length);
  solid::test::expect_tangent_matches_finite_differences(problem, u, 1.0, "contact", 1e-5);
}

// An elastic cylinder cap (radius R, 60° of arc, plane strain) pushed up against a rigid flat: the
// contact half-width and peak pressure against Hertz's line contact, a = √(4FR/(πE*)),
// p0 = 2F/(πa), E* = E/(1 − ν²), with F the transmitted force. The half-width is measured from the
// computed pressure's second moment (a²/4 of ∫p for an elliptical distribution).
TEST(MortarContact, HertzLineContactOfACylinderOnARigidFlat) {
  const double radius = 1.0, youngs = 1.0, nu = 0.3;
  const double c30 = std::cos(std::numbers::pi / 6);
  Points2 net(6, 2);
  net << -0.5, 0.0, 0.0, 0.0, 0.5, 0.0,  // bottom: the chord's line y = 0
      -0.5, c30, 0.0, 1.0 / c30, 0.5, c30;   // top: the arc from 120° to 60°
  Eigen::VectorXd w(6);
  w << 1, c30, 1, 1, c30, 1;
  SplineSurface cap(SplineBasis::open_uniform(2, 1, 0, 1), SplineBasis::open_uniform(1, 1, 0, 1), net, w);
  cap = cap.elevated_v();
  // Fine spans where the contact will be, graded spans across the depth toward the top.
  std::vector<double> us, vs;
  for (int k = 1; k < 12; ++k) us.push_back(0.4 * k / 12.0);
  for (int k = 0; k <= 60; ++k) us.push_back(0.4 + 0.2 * k / 60.0);
  for (int k = 1; k < 12; ++k) us.push_back(0.6 + 0.4 * k / 12.0);
  for (int k = 1; k < 14; ++k) vs.push_back(1.0 - std::pow(1.0 - k / 14.0, 2.5));
  cap = cap.refined_u(us).refined_v(vs);
  solid::SolidProblem problem(solid::IgaSpace(cap), std::make_shared<solid::LinearElastic>(youngs, nu, 1.0));
  Points2 flat(2, 2);
  flat << -2.0, radius, 2.0, radius;
  auto contact = std::make_shared<MortarContact>(
      problem.space(), RigidTool{SplineCurve(SplineBasis::open_uniform(1, 1, 0, 1), flat)}, 1e4);
  problem.add_interaction(contact);
  problem.fix_side(numerics::Side::bottom, 0);
  problem.fix_side(numerics::Side::bottom, 1, 4e-3, [](double t) { return t; });
  solid::TimeIntegrationOptions options;
  options.scheme = solid::TimeScheme::quasi_static;
  options.dt = 0.5;
  options.end_time = 1.0;
  options.relative_tolerance = 1e-10;
  solid::TimeIntegrator integrator(problem, options);
  const auto report = integrator.run();
  ASSERT_TRUE(report.completed) << report.reason;
  const ContactState s = contact->state(integrator.u());
  const double force = -s.force.y();
  double moment = 0.0, total = 0.0;
  // Trapezoid sums over the surface points (sorted by x): ∫p dx and ∫p x² dx.
  for (size_t q = 1; q < s.point_x.size(); ++q) {
    const double dx = s.point_x[q] - s.point_x[q - 1];
    total += 0.5 * dx * (s.point_pressure[q] + s.point_pressure[q - 1]);
    moment += 0.5 * dx * (s.point_pressure[q] * s.point_x[q] * s.point_x[q] +
                          s.point_pressure[q - 1] * s.point_x[q - 1] * s.point_x[q - 1]);
  }
  EXPECT_NEAR(total, force, 0.01 * force);
  const double e_star = youngs / (1 - nu * nu);
  const double a_hertz = std::sqrt(4 * force * radius / (std::numbers::pi * e_star));
  const double p0_hertz = 2 * force / (std::numbers::pi * a_hertz);
  const double a_measured = 2 * std::sqrt(moment / total);
  EXPECT_GT(a_hertz, 0.02);  // a real contact patch, resolved by ~13 spans
  EXPECT_LT(a_hertz, 0.1);
  EXPECT_NEAR(a_measured, a_hertz, 0.02 * a_hertz) << "F = " << force;
  EXPECT_NEAR(s.max_pressure, p0_hertz, 0.02 * p0_hertz) << "F = " << force;
  EXPECT_NEAR(s.force.x(), 0.0, 1e-6 * force);  // symmetric: no tangential resultant
  std::printf("Hertz: F %.6g a %.6g (Hertz %.6g) p0 %.6g (Hertz %.6g), %d Newton iterations, assembly %.2f s, solve %.2f s\n",
              force, a_measured, a_hertz, s.max_pressure, p0_hertz, report.newton_iterations, report.seconds_assembly,
              report.seconds_solve);
}

}  // namespace
}  // namespace mufric::contact
