// Mortar penalty contact with a rigid tool: the contact patch test, the exact linearisation against
// finite differences, and Hertz's line contact of an elastic cylinder on a rigid flat.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>

#include "common/error.hpp"
#include "micro/contact/adhesion_table.hpp"
#include "micro/contact/interface_laws.hpp"
#include "micro/contact/mortar_contact.hpp"
#include "micro/solid/heat_conduction.hpp"
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

// The patch tests' set-up: a linear elastic flat chip (7 spans along, `through` across) fixed at its
// bottom and pressed there by `pressure` onto a flat rigid tool that starts 1e-6 inside it, so contact
// is active from the first iteration; `law` at the interface (frictionless by default).
struct FlatChipOnTool {
  static constexpr double period = 1.0, height = 0.5, penalty = 1e3;
  std::unique_ptr<solid::SolidProblem> chip;
  std::shared_ptr<MortarContact> contact;
};

FlatChipOnTool flat_chip_on_tool(double pressure, ContactInterface law = {}, int through = 3) {
  using C = FlatChipOnTool;
  auto chip = std::make_unique<solid::SolidProblem>(
      solid::IgaSpace(SplineSurface::extruded(flat_chip_surface(C::height, C::period, 7), 0.0, 2, through)),
      std::make_shared<solid::LinearElastic>(1.0, 0.3, 1.0));
  const RigidTool tool{flat_tool(C::height - 1e-6, C::period, 11, 2)};
  auto contact = std::make_shared<MortarContact>(chip->space(), tool, C::penalty, 0, std::move(law));
  chip->add_interaction(contact);
  chip->fix_side(numerics::Side::bottom, 0);
  chip->add_load({numerics::Side::bottom, Eigen::Vector2d::Zero(), pressure, {}});
  return {std::move(chip), std::move(contact)};
}

TEST(MortarContact, PatchTestTransmitsUniformPressureAndNoShear) {
  const double pressure = 1e-3, period = FlatChipOnTool::period;
  auto [chip, contact] = flat_chip_on_tool(pressure);
  solid::SolidProblem& problem = *chip;
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

// Two rough periodic surfaces over [0, 1], the tool lowered into the chip's peaks: part of the
// surface in contact, part not.
struct RoughPair {
  SplineCurve chip_surface, tool_surface;
};
RoughPair rough_surfaces_in_contact() {
  spline::RoughnessSpec spec;
  spec.length = 1.0;
  spec.ra = 0.02;
  spec.correlation_length = 0.1;
  spec.samples = 256;
  const SplineCurve chip_surface = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 2, 24).curve;
  spec.seed = 9;
  const SplineCurve tool = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 3, 30).curve;
  Points2 lowered = tool.points();
  lowered.col(1).array() += 0.03;
  return {chip_surface, SplineCurve(tool.basis(), lowered, {}, tool.shift())};
}

// The rough pair's chip perturbed at random, that state committed, then slid along x by amounts
// that leave some points in stick and push others into slip: the state the frictional tangent
// tests compare at.
Eigen::VectorXd committed_then_slid(const solid::SolidProblem& problem, MortarContact& contact) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd u(problem.dof_count());
  for (auto& x : u) x = 2e-3 * unit(rng);
  contact.commit(u);
  for (Eigen::Index i = 0; i < u.size(); i += 2) u(i) += 2e-3 * (1.0 + unit(rng));
  return u;
}

// Points in contact that slip at the limit limit_of(q, P) (to 1e-12 of P) and those that stick.
struct StickSlip {
  int stick = 0, slip = 0;
};
template <class Limit>
StickSlip count_stick_slip(const ContactState& s, Limit limit_of) {
  StickSlip n;
  for (size_t q = 0; q < s.point_shear.size(); ++q) {
    const double p = s.point_pressure[q];
    if (p <= 0.0) continue;
    const bool slipping = std::abs(std::abs(s.point_shear[q]) - limit_of(q, p)) < 1e-12 * p;
    slipping ? ++n.slip : ++n.stick;
  }
  std::cout << "points in stick " << n.stick << ", in slip " << n.slip << "\n";
  return n;
}

TEST(MortarContact, TangentIsTheExactLinearisationOnARoughTool) {
  const auto [chip_surface, tool_surface] = rough_surfaces_in_contact();
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

// ---- Coulomb's law at the contact points --------------------------------------------------------

ContactInterface with_law(std::shared_ptr<const InterfaceLaw> law, double tangential_penalty) {
  return {.law = std::move(law), .tangential_penalty = tangential_penalty};
}

ContactInterface coulomb(double adhesive_coefficient, double tangential_penalty = 0.0) {
  return with_law(std::make_shared<CoulombLaw>(adhesive_coefficient), tangential_penalty);
}

// The contact's points all at one chip state (k, T), given through the provider a run gives them by.
std::shared_ptr<SampledPointStates> uniform_point_states(MortarContact& contact, double shear_strength, double temperature,
                                                         double sliding_velocity = 1.0) {
  const size_t points = contact.surface_positions().size();
  auto states = std::make_shared<SampledPointStates>(points, sliding_velocity);
  states->set_shear_strength(std::vector<double>(points, shear_strength));
  states->set_temperature(std::vector<double>(points, temperature));
  contact.set_point_states(states);
  return states;
}

// The patch test's flat chip pressed uniformly onto a flat tool, its state committed, then slid
// rigidly along the tool by d: every point carries τ = −ε_t d while ε_t d ≤ μ_a p (stick) and
// τ = −μ_a p beyond (slip), so the resultant's ratio is μ_a exactly (Coulomb's law, closed form).
TEST(CoulombContact, AFlatChipSlidUnderUniformPressureCarriesTheLawsShear) {
  const double pressure = 1e-3, tangential = 400.0, mu_a = 0.3, period = FlatChipOnTool::period;
  auto [chip, contact] = flat_chip_on_tool(pressure, coulomb(mu_a, tangential));
  solid::SolidProblem& problem = *chip;
  EXPECT_FALSE(contact->symmetric_tangent());
  const Eigen::VectorXd pressed = solid::test::solve_static(problem);
  contact->commit(pressed);
  const double stick_limit = mu_a * pressure / tangential;  // the slide at which stick ends
  for (const double fraction : {0.5, -0.5, 3.0, -3.0}) {
    const double d = fraction * stick_limit;
    Eigen::VectorXd slid = pressed;
    for (Eigen::Index i = 0; i < slid.size(); i += 2) slid(i) += d;
    const ContactState s = contact->state(slid);
    const double expected_shear = std::abs(fraction) <= 1.0 ? -tangential * d : -std::copysign(mu_a * pressure, d);
    for (size_t q = 0; q < s.point_shear.size(); ++q) {
      EXPECT_NEAR(s.point_pressure[q], pressure, 1e-9 * pressure);
      EXPECT_NEAR(s.point_shear[q], expected_shear, 1e-6 * mu_a * pressure) << "slide " << fraction << ", x " << s.point_x[q];
    }
    EXPECT_NEAR(s.force.x(), expected_shear * period, 1e-6 * mu_a * pressure * period) << "slide " << fraction;
    EXPECT_NEAR(s.force.y(), -pressure * period, 1e-9 * pressure * period);
    if (std::abs(fraction) > 1.0) {
      EXPECT_NEAR(std::abs(s.force.x() / s.force.y()), mu_a, 1e-9);
    }
  }
  // A committed slip moves the anchors: sliding back by less than twice the stick limit sticks.
  Eigen::VectorXd slid = pressed;
  for (Eigen::Index i = 0; i < slid.size(); i += 2) slid(i) += 3.0 * stick_limit;
  contact->commit(slid);
  for (Eigen::Index i = 0; i < slid.size(); i += 2) slid(i) -= stick_limit;
  const ContactState back = contact->state(slid);
  for (size_t q = 0; q < back.point_shear.size(); ++q) {
    // −μ_a p + ε_t d = 0, up to the offset's first-order arc length on the unevenly parameterised tool
    EXPECT_NEAR(back.point_shear[q], 0.0, 1e-5 * mu_a * pressure) << "x " << back.point_x[q];
  }
}

// The flat chip pressed and then slid rigidly along the tool in equal steps, each committed: a
// point sticks until its offset reaches μ_a p/ε_t and slips by every step's length after, so the
// dissipated energy is μ_a p L (n d − μ_a p/ε_t) (closed form); a step back within the stick range
// dissipates nothing. The chip receives β of each step's dissipation: the heat conduction's heat
// content rises by exactly that (an energy balance to solver tolerance), all of it entering at the
// top surface. (28 spans through the thickness: the consistent capacity matrix spreads a surface heat
// a little through the layer, decaying ~0.4× per span; with 3 spans 6 % of it would reach the held
// face, with 28 under 1e-9.)
TEST(CoulombContact, SlipDissipatesMuPTimesTheSlipAndTheChipReceivesItsShare) {
  const double pressure = 1e-3, tangential = 400.0, mu_a = 0.3, period = FlatChipOnTool::period;
  const double step = 2e-6, partition = 0.7;
  const int steps = 7;
  ContactInterface law = coulomb(mu_a, tangential);
  law.heat_partition = partition;
  auto [chip, contact] = flat_chip_on_tool(pressure, law, 28);
  solid::SolidProblem& problem = *chip;
  Eigen::VectorXd u = solid::test::solve_static(problem);
  contact->commit(u);
  EXPECT_EQ(contact->dissipated_energy(), 0.0);
  const double stick_offset = mu_a * pressure / tangential;  // 7.5e-7: the first step slips part of its length
  ASSERT_LT(stick_offset, step);

  solid::HeatConduction heat(problem.space(), {.conductivity = 0.0, .density = 2.0, .specific_heat = 3.0,
                                               .held_side = numerics::Side::bottom, .held_temperature = 0.0});
  std::vector<solid::MaterialState> states(problem.space().quadrature().size());
  for (auto& st : states) st.temperature = 0.0;  // the conduction's own start: no adiabatic heat
  std::string reason;
  const auto node_count = problem.space().node_count();
  double received = 0.0;
  for (int k = 0; k < steps; ++k) {
    for (Eigen::Index i = 0; i < u.size(); i += 2) u(i) += step;
    contact->commit(u);
    const Eigen::VectorXd nodal = contact->frictional_heat(node_count);
    EXPECT_NEAR(nodal.sum(), partition * contact->step_dissipated_energy(), 1e-12 * contact->step_dissipated_energy());
    for (const int node : problem.space().side_nodes(numerics::Side::bottom)) EXPECT_EQ(nodal(node), 0.0);
    const double before = heat.heat_content();
    ASSERT_TRUE(heat.step(u, 1e-3, states, reason, nodal)) << reason;
    received += heat.heat_content() - before;
  }
  const double expected = mu_a * pressure * period * (steps * step - stick_offset);
  // (the offset is the arc length to first order on the unevenly parameterised flat tool: 1e-6 relative)
  EXPECT_NEAR(contact->dissipated_energy(), expected, 1e-6 * expected);
  EXPECT_NEAR(received, partition * contact->dissipated_energy(), 1e-9 * received);
  // Back by half the stick range: every point sticks, nothing is dissipated.
  for (Eigen::Index i = 0; i < u.size(); i += 2) u(i) -= 0.5 * stick_offset;
  contact->commit(u);
  EXPECT_EQ(contact->step_dissipated_energy(), 0.0);
  EXPECT_NEAR(contact->dissipated_energy(), expected, 1e-6 * expected);
}

ContactInterface shear_factor_law(double shear_factor, double tangential) {
  return with_law(std::make_shared<ShearFactorLaw>(shear_factor), tangential);
}
ContactInterface zorev_law(double shear_factor, double adhesive_coefficient, double tangential) {
  return with_law(std::make_shared<ZorevLaw>(LawCoefficients{adhesive_coefficient, shear_factor}), tangential);
}

// The same slid flat chip under the shear-factor law, τ = m k in slip (within e^−20 of it at these
// pressures, its onset aside: 2e-9, inside the tolerance), and
// under Zorev's, τ = min(μ_a p, m k): the Coulomb branch below the switch, the shear branch above it
// (closed forms).
TEST(YieldLimitedContact, AFlatChipSlidCarriesMTimesKOrZorevsLowerBranch) {
  const double pressure = 1e-3, tangential = 400.0, mu_a = 0.3, m = 0.5;
  struct Case {
    ContactInterface law;
    double k;               // the chip's shear yield stress, uniform
    double expected_limit;  // the slip shear the law gives
  };
  const std::vector<Case> cases = {
      {shear_factor_law(m, tangential), 2e-4, m * 2e-4},
      {shear_factor_law(m, tangential), 2e-3, m * 2e-3},
      {zorev_law(m, mu_a, tangential), 2e-3, mu_a * pressure},  // μ_a p = 3e-4 < m k = 1e-3: Coulomb branch
      {zorev_law(m, mu_a, tangential), 2e-4, m * 2e-4}};        // m k = 1e-4 < μ_a p: the shear branch
  for (const auto& c : cases) {
    auto [chip, contact] = flat_chip_on_tool(pressure, c.law);
    const size_t points = contact->surface_positions().size();
    Eigen::VectorXd probe = Eigen::VectorXd::Zero(chip->dof_count());
    EXPECT_THROW(contact->state(probe), Error);  // no provider of k yet
    auto states = std::make_shared<SampledPointStates>(points, 1.0);
    contact->set_point_states(states);
    EXPECT_THROW(contact->state(probe), Error);  // a provider, but k not given yet
    states->set_shear_strength(std::vector<double>(points, c.k));
    const Eigen::VectorXd pressed = solid::test::solve_static(*chip);
    contact->commit(pressed);
    for (const double fraction : {0.5, 3.0}) {
      const double d = fraction * c.expected_limit / tangential;
      Eigen::VectorXd slid = pressed;
      for (Eigen::Index i = 0; i < slid.size(); i += 2) slid(i) += d;
      const ContactState s = contact->state(slid);
      const double expected = fraction <= 1.0 ? -tangential * d : -c.expected_limit;
      for (size_t q = 0; q < s.point_shear.size(); ++q) {
        // (stick: the offset's arc length is first order in ξ − ξ_a on the unevenly parameterised tool)
        EXPECT_NEAR(s.point_shear[q], expected, 1e-5 * c.expected_limit) << "k " << c.k << ", slide " << fraction;
      }
    }
  }
}

// The slid flat chip with half its points wetted: in slip a wetted point carries the law's wetted
// coefficient (μ_wet p for Coulomb, m_wet k for the shear factor, μ_wet p for a table whose dry μ_a is
// higher), a dry one the dry coefficient (closed forms); the state reports which points are wetted and
// their length in contact; unset, every point is dry again.
TEST(WettedContact, WettedPointsTakeTheWettedCoefficients) {
  const double pressure = 1e-3, tangential = 400.0, period = FlatChipOnTool::period;
  const double mu_a = 0.3, m = 0.5, k = 2e-3, mu_wet = 0.05, m_wet = 0.1;
  const auto table_path = std::filesystem::temp_directory_path() / "mufric_wetted_table.csv";
  {
    std::ofstream t(table_path);
    t << "contact_pressure[Pa],sliding_velocity[m/s],temperature[K],mu_a\n";
    for (const char* p : {"0", "1"}) {
      for (const char* v : {"0", "10"}) {
        for (const char* T : {"1", "2000"}) t << p << "," << v << "," << T << ",0.4\n";
      }
    }
  }
  struct Case {
    ContactInterface law;
    double dry_limit, wet_limit;  // the slip shear of a dry and of a wetted point
  };
  const auto table = std::make_shared<const AdhesionTable>(AdhesionTable::read(table_path.string()));
  const std::vector<Case> cases = {
      {with_law(std::make_shared<CoulombLaw>(mu_a, mu_wet), tangential), mu_a * pressure, mu_wet * pressure},
      // m k reached from an opening point by the law's steep Childs onset: 1 − e^(−μ₀ P/(m k)) of it.
      {with_law(std::make_shared<ShearFactorLaw>(m, m_wet), tangential),
       -m * k * std::expm1(-kShearFactorOnsetCoefficient * pressure / (m * k)),
       -m_wet * k * std::expm1(-kShearFactorOnsetCoefficient * pressure / (m_wet * k))},
      {with_law(std::make_shared<TableLaw>(table, mu_wet), tangential), 0.4 * pressure, mu_wet * pressure}};
  for (const Case& c : cases) {
    auto [chip, contact] = flat_chip_on_tool(pressure, c.law);
    const std::vector<Eigen::Vector2d> at = contact->surface_positions();
    const auto states = uniform_point_states(*contact, k, 300.0);
    std::vector<char> wetted(at.size(), 0);
    for (size_t q = 0; q < at.size(); ++q) wetted[q] = at[q].x() < 0.5 * period ? 1 : 0;
    EXPECT_THROW(states->set_wetted(std::vector<char>(at.size() + 1, 1)), Error);
    states->set_wetted(wetted);
    const Eigen::VectorXd pressed = solid::test::solve_static(*chip);
    contact->commit(pressed);
    const double d = 3.0 * std::max(c.dry_limit, c.wet_limit) / tangential;  // slip everywhere
    Eigen::VectorXd slid = pressed;
    for (Eigen::Index i = 0; i < slid.size(); i += 2) slid(i) += d;
    const ContactState s = contact->state(slid);
    double wetted_length = 0.0;
    for (size_t q = 0; q < s.point_shear.size(); ++q) {
      EXPECT_EQ(s.point_wetted[q], wetted[q]);
      const double expected = -(wetted[q] != 0 ? c.wet_limit : c.dry_limit);
      EXPECT_NEAR(s.point_shear[q], expected, 1e-9 * c.dry_limit) << "x " << s.point_x[q];
      if (wetted[q] != 0) wetted_length += s.point_weight[q];
    }
    EXPECT_NEAR(s.wetted_contact_length, wetted_length, 1e-12);
    EXPECT_GT(wetted_length, 0.0);
    EXPECT_LT(wetted_length, s.contact_length - 0.1);
    states->set_wetted({});
    const ContactState dry = contact->state(slid);
    for (size_t q = 0; q < dry.point_shear.size(); ++q) EXPECT_NEAR(dry.point_shear[q], -c.dry_limit, 1e-9 * c.dry_limit);
    EXPECT_EQ(dry.wetted_contact_length, 0.0);
  }
  std::filesystem::remove(table_path);
}

// The tangent of Zorev's law against central differences, with points on both branches and in stick
// (k varies along the surface so that the switch falls inside the contact).
TEST(YieldLimitedContact, ZorevTangentIsTheExactLinearisationOnBothBranches) {
  const auto [chip_surface, tool_surface] = rough_surfaces_in_contact();
  solid::SolidProblem problem(solid::IgaSpace(SplineSurface::extruded(chip_surface, -0.5, 2, 3)),
                              std::make_shared<solid::LinearElastic>(1e-2, 0.3, 1.0));
  const double mu_a = 0.3, m = 0.5;
  auto contact = std::make_shared<MortarContact>(problem.space(), RigidTool{tool_surface}, 50.0, 0,
                                                 zorev_law(m, mu_a, 50.0));
  std::vector<double> k;
  for (const auto& x : contact->surface_positions()) k.push_back(0.4 * (1.0 + std::sin(2 * std::numbers::pi * x.x())));
  auto states = std::make_shared<SampledPointStates>(k.size(), 1.0);
  states->set_shear_strength(k);
  contact->set_point_states(states);
  problem.add_interaction(contact);
  const Eigen::VectorXd u = committed_then_slid(problem, *contact);
  const ContactState s = contact->state(u);
  int stick = 0, coulomb_branch = 0, shear_branch = 0;
  for (size_t q = 0; q < s.point_shear.size(); ++q) {
    const double p = s.point_pressure[q];
    if (p <= 0.0) continue;
    const double tau = std::abs(s.point_shear[q]);
    if (std::abs(tau - mu_a * p) < 1e-12 * p && mu_a * p <= m * k[q]) {
      ++coulomb_branch;
    } else if (std::abs(tau - m * k[q]) < 1e-12 && m * k[q] < mu_a * p) {
      ++shear_branch;
    } else {
      ++stick;
    }
  }
  std::cout << "points in stick " << stick << ", slip at mu_a p " << coulomb_branch << ", at m k " << shear_branch << "\n";
  ASSERT_GT(stick, 0);
  ASSERT_GT(coulomb_branch, 0);
  ASSERT_GT(shear_branch, 0);
  solid::test::expect_tangent_matches_finite_differences(problem, u, 1.0, "zorev contact", 1e-5);
}

// ---- Childs' smooth Zorev, and the registry every law joins -------------------------------------

// Childs' limit against what it must be independently of its formula's code: Coulomb's μ_a P where
// μ_a P ≪ m k, the yield shear m k where μ_a P ≫ m k, exactly m k (1 − e^(−x)) for n = 1 (written
// out by hand), below min(μ_a P, m k) everywhere; its slope against central differences; Zorev's
// corner approached as n grows; a wetted spot's wetted coefficients.
TEST(ChildsLaw, BlendsCoulombIntoTheYieldShearWithTheSlopeItsLimitHas) {
  const double mu_a = 0.3, m = 0.6, k = 400e6;
  const double yield_shear = m * k;
  ContactPointState point{.shear_strength = k};
  for (const double n : {0.5, 1.0, 2.0, 5.0, 20.0}) {
    const ChildsLaw law({mu_a, m}, n);
    for (const double pressure : {1e3, 1e6, 1e8, 4e8, 8e8, 2e9, 1e10, 1e12}) {
      point.pressure = pressure;
      const SlipLimit limit = law.slip_limit(point);
      EXPECT_LE(limit.shear, std::min(mu_a * pressure, yield_shear) * (1.0 + 1e-15)) << "n " << n << ", P " << pressure;
      EXPECT_GT(limit.shear, 0.0);
      const double step = 1e-6 * pressure;
      point.pressure = pressure + step;
      const double above = law.slip_limit(point).shear;
      point.pressure = pressure - step;
      const double below = law.slip_limit(point).shear;
      EXPECT_NEAR(limit.dshear_dpressure, (above - below) / (2 * step), 1e-6 * mu_a) << "n " << n << ", P " << pressure;
    }
    // x = 1.25e-6: Coulomb's branch, below it by a share xⁿ/(2n) to first order.
    point.pressure = 1e3;
    const double x = mu_a * 1e3 / yield_shear;
    EXPECT_NEAR(law.slip_limit(point).shear, mu_a * 1e3, (std::pow(x, n) / n + 1e-14) * mu_a * 1e3) << n;
    EXPECT_NEAR(law.slip_limit(point).dshear_dpressure, mu_a, (2 * std::pow(x, n) + 1e-14) * mu_a) << n;
    point.pressure = 1e12;  // x = 1250: the yield shear, flat in P
    EXPECT_NEAR(law.slip_limit(point).shear, yield_shear, 1e-12 * yield_shear) << n;
    EXPECT_LT(law.slip_limit(point).dshear_dpressure, 1e-12 * mu_a) << n;
  }
  const ChildsLaw exponential({mu_a, m}, 1.0);
  point.pressure = 8e8;
  EXPECT_NEAR(exponential.slip_limit(point).shear, yield_shear * (1.0 - std::exp(-mu_a * 8e8 / yield_shear)), 1e-9 * yield_shear);
  // At Zorev's corner (μ_a P = m k) the blend is (1 − 1/e)^(1/n) of it: 0.977 at n = 20.
  point.pressure = yield_shear / mu_a;
  EXPECT_NEAR(ChildsLaw({mu_a, m}, 20.0).slip_limit(point).shear, std::pow(1.0 - std::exp(-1.0), 1.0 / 20.0) * yield_shear,
              1e-12 * yield_shear);
  // Away from the corner, n = 20 is Zorev's law.
  const ZorevLaw zorev({mu_a, m});
  for (const double pressure : {2e8, 1.2e9}) {
    point.pressure = pressure;
    EXPECT_NEAR(ChildsLaw({mu_a, m}, 20.0).slip_limit(point).shear, zorev.slip_limit(point).shear, 1e-3 * yield_shear);
  }
  // A wetted spot takes the wetted pair.
  point.pressure = 1e12;
  point.wetted = true;
  EXPECT_NEAR(ChildsLaw({mu_a, m}, 2.0, {0.05, 0.1}).slip_limit(point).shear, 0.1 * k, 1e-12 * k);
  // A chip without strength there carries no shear, and out-of-range coefficients are refused.
  point.shear_strength = 0.0;
  EXPECT_EQ(ChildsLaw({mu_a, m}, 2.0).slip_limit(point).shear, 0.0);
  EXPECT_THROW(ChildsLaw({mu_a, m}, 0.1), Error);
  EXPECT_THROW(ChildsLaw({mu_a, 1.5}, 2.0), Error);
}

// Childs' tangent against central differences on the rough pair, with points in stick and in slip on
// the blend: k at each point is set from its pressure so that μ_a P/(m k) is 0.5, 1 or 2 (the
// pressure depends on the gap alone, so k does not move it), where neither asymptote is the law.
// The shear-factor law reaches m k from an opening point (issue 63: taken as m k at any P > 0 it jumped
// where asperity contacts open and close, and the default scene cut back 883 times without finishing):
// 0 as P → 0 with slope μ₀, m k within e^−20 from P = m k on, and its slope the limit's derivative.
TEST(ShearFactorLaw, ReachesMKFromAnOpeningPointWithTheSlopeItsLimitHas) {
  const double m = 0.5, k = 2e8, mk = m * k;
  const ShearFactorLaw law(m);
  ContactPointState point;
  point.shear_strength = k;
  point.pressure = 1e-3 * mk;  // barely in contact: Coulomb-like, μ₀ P
  EXPECT_NEAR(law.slip_limit(point).shear, kShearFactorOnsetCoefficient * point.pressure, 0.02 * kShearFactorOnsetCoefficient * point.pressure);
  for (const double share : {1.0, 3.0, 30.0}) {
    point.pressure = share * mk;
    EXPECT_NEAR(law.slip_limit(point).shear, mk, 2.1e-9 * mk) << share;
  }
  for (const double share : {0.01, 0.05, 0.2, 1.0}) {
    point.pressure = share * mk;
    const double h = 1e-6 * point.pressure;
    ContactPointState above = point, below = point;
    above.pressure += h;
    below.pressure -= h;
    const double slope = (law.slip_limit(above).shear - law.slip_limit(below).shear) / (2.0 * h);
    EXPECT_NEAR(law.slip_limit(point).dshear_dpressure, slope, 1e-6 * kShearFactorOnsetCoefficient) << share;
  }
}

TEST(ChildsLaw, ContactTangentIsTheExactLinearisationOnTheBlend) {
  const auto [chip_surface, tool_surface] = rough_surfaces_in_contact();
  solid::SolidProblem problem(solid::IgaSpace(SplineSurface::extruded(chip_surface, -0.5, 2, 3)),
                              std::make_shared<solid::LinearElastic>(1e-2, 0.3, 1.0));
  const double mu_a = 0.3, m = 0.5;
  const auto law = std::make_shared<ChildsLaw>(LawCoefficients{mu_a, m}, 2.0);
  auto contact = std::make_shared<MortarContact>(problem.space(), RigidTool{tool_surface}, 50.0, 0, with_law(law, 5.0));
  const size_t points = contact->surface_positions().size();
  auto states = std::make_shared<SampledPointStates>(points, 1.0);
  states->set_shear_strength(std::vector<double>(points, 1.0));
  contact->set_point_states(states);
  problem.add_interaction(contact);
  const Eigen::VectorXd u = committed_then_slid(problem, *contact);
  const ContactState at_u = contact->state(u);
  std::vector<double> k(points, 1.0);
  const std::array<double, 3> blend{0.5, 1.0, 2.0};
  for (size_t q = 0; q < points; ++q) {
    if (at_u.point_pressure[q] > 0.0) k[q] = mu_a * at_u.point_pressure[q] / (m * blend[q % 3]);
  }
  states->set_shear_strength(k);
  const StickSlip n = count_stick_slip(contact->state(u), [&](size_t q, double p) {
    return law->slip_limit({.pressure = p, .shear_strength = k[q]}).shear;
  });
  ASSERT_GT(n.stick, 3);
  ASSERT_GT(n.slip, 3);
  solid::test::expect_tangent_matches_finite_differences(problem, u, 1.0, "childs contact", 1e-5);
}

// Every registered law: a unique name found again by it, frictionless first (the default), the keys
// it declares read by its reader (a reader reading an undeclared key is a logic error, so the scene's
// warnings about other laws' keys are right), and a law whose name is the entry's.
TEST(InterfaceLawRegistry, EveryLawIsFoundByItsNameAndReadsExactlyItsDeclaredKeys) {
  const auto table_path = std::filesystem::temp_directory_path() / "mufric_registry_table.csv";
  std::ofstream(table_path) << "contact_pressure[Pa],sliding_velocity[m/s],temperature[K],mu_a\n0,1,300,0.2\n1,1,300,0.2\n";
  // Answers every key with a mid-range value (the table's path for a file) and records what was read.
  struct RecordingKeys final : LawKeys {
    std::string table;
    std::vector<std::string> read;
    double required_number(std::string_view key, double lo, double hi, std::string_view) override {
      read.emplace_back(key);
      return 0.5 * (lo + hi);
    }
    double number(std::string_view key, double, double lo, double hi) override { return required_number(key, lo, hi, ""); }
    std::string required_file(std::string_view key, std::string_view) override {
      read.emplace_back(key);
      return table;
    }
    [[noreturn]] void fail(std::string_view key, const std::string& message) override {
      throw Error(std::string(key) + ": " + message);
    }
  };
  ASSERT_GE(interface_laws().size(), 6U);
  EXPECT_EQ(interface_laws().front().name, "frictionless");
  for (const auto& entry : interface_laws()) {
    EXPECT_EQ(find_interface_law(entry.name), &entry);
    RecordingKeys keys;
    keys.table = table_path.string();
    const auto law = entry.read(keys);
    ASSERT_NE(law, nullptr) << entry.name;
    EXPECT_EQ(law->name(), entry.name);
    std::vector<std::string> declared(entry.keys.begin(), entry.keys.end());
    std::sort(declared.begin(), declared.end());
    std::sort(keys.read.begin(), keys.read.end());
    EXPECT_EQ(keys.read, declared) << entry.name;
    EXPECT_EQ(law->frictional(), entry.name != "frictionless");
  }
  EXPECT_EQ(find_interface_law("sticky"), nullptr);
  EXPECT_NE(interface_law_names().find("frictionless, coulomb"), std::string::npos);
  std::filesystem::remove(table_path);
}

// A rigid facet of slope α pressed uniformly onto a chip whose surface lies parallel to it (a sheared
// periodic cell), then slid along the facet in slip: the force on the facet leans from its normal by
// arctan μ_a against the sliding, so its ratio in the x–y axes is tan(α + arctan μ_a) (statics of
// the inclined plane with Coulomb friction), whatever the parameterisations of tool and chip.
TEST(CoulombContact, ARigidFacetOfSlopeAlphaInSlipLeansByArctanMu) {
  const double period = 1.0, height = 0.5, penalty = 1e3, tangential = 400.0, mu_a = 0.3;
  for (const double alpha_deg : {5.0, 20.0}) {
    const double slope = std::tan(alpha_deg * std::numbers::pi / 180.0);
    const Eigen::Vector2d shift(period, period * slope);
    // The chip: a parallelogram cell, bottom along y = x tan α, top along y = h + x tan α.
    const int spans = 7;
    Points2 net(2 * spans, 2);
    for (int i = 0; i < spans; ++i) {
      const double x = period * i / spans;
      net.row(i) << x, x * slope;
      net.row(i + spans) << x, height + x * slope;
    }
    SplineSurface cell(SplineBasis::periodic_uniform(2, spans, 0, 1), SplineBasis::open_uniform(1, 1, 0.0, 1.0), net, {},
                       shift);
    cell = cell.elevated_v().subdivided(1, 3);
    solid::SolidProblem problem(solid::IgaSpace(cell), std::make_shared<solid::LinearElastic>(1.0, 0.3, 1.0));
    // The facet 1e-6 (vertically) into the chip, its control points spaced unevenly.
    const int tool_points = 11;
    Points2 facet(tool_points, 2);
    for (int i = 0; i < tool_points; ++i) {
      const double x = period * (i + 0.3 * std::sin(1.7 * (i + 2))) / tool_points;
      facet.row(i) << x, height - 1e-6 + x * slope;
    }
    auto contact = std::make_shared<MortarContact>(
        problem.space(), RigidTool{SplineCurve(SplineBasis::periodic_uniform(3, tool_points, 0, 1), facet, {}, shift)},
        penalty, 0, coulomb(mu_a, tangential));
    Eigen::VectorXd u = Eigen::VectorXd::Zero(problem.dof_count());
    contact->commit(u);
    const double pressure = penalty * 1e-6 * std::cos(std::atan(slope));  // the normal gap's penalty
    const Eigen::Vector2d along(std::cos(std::atan(slope)), std::sin(std::atan(slope)));
    for (const double direction : {1.0, -1.0}) {
      const Eigen::Vector2d d = direction * 3.0 * mu_a * pressure / tangential * along;  // well into slip
      for (Eigen::Index i = 0; i < u.size(); i += 2) u.segment<2>(i) = d;
      const ContactState s = contact->state(u);
      // Up the facet (+t) the friction on the chip points down it: the chip pushes the facet forward
      // and up, F_x/F_y on the chip = −tan(α − arctan μ_a); down it, −tan(α + arctan μ_a).
      const double expected = -std::tan(std::atan(slope) - direction * std::atan(mu_a));
      EXPECT_NEAR(s.force.x() / s.force.y(), expected, 1e-9) << "alpha " << alpha_deg << ", direction " << direction;
      EXPECT_NEAR(std::hypot(s.force.x(), s.force.y()),
                  pressure * std::hypot(1.0, mu_a) * period / std::cos(std::atan(slope)), 1e-6 * pressure);
    }
  }
}

// The consistent (unsymmetric) tangent of the frictional contact against central differences, on
// rough surfaces with points in stick and in slip at once (a soft chip, so that the contact's part
// of the residual dominates what is compared).
TEST(CoulombContact, TangentIsTheExactLinearisationInStickAndSlip) {
  const auto [chip_surface, tool_surface] = rough_surfaces_in_contact();
  solid::SolidProblem problem(solid::IgaSpace(SplineSurface::extruded(chip_surface, -0.5, 2, 3)),
                              std::make_shared<solid::LinearElastic>(1e-2, 0.3, 1.0));
  const double mu_a = 0.3;
  auto contact = std::make_shared<MortarContact>(problem.space(), RigidTool{tool_surface}, 50.0, 0, coulomb(mu_a, 50.0));
  problem.add_interaction(contact);
  const Eigen::VectorXd u = committed_then_slid(problem, *contact);
  const StickSlip n = count_stick_slip(contact->state(u), [&](size_t, double p) { return mu_a * p; });
  ASSERT_GT(n.stick, 3);
  ASSERT_GT(n.slip, 3);
  EXPECT_EQ(problem.tangent_storage(), numerics::MatrixStorage::full);
  solid::test::expect_tangent_matches_finite_differences(problem, u, 1.0, "coulomb contact", 1e-5);
}


// ---- The tabulated adhesive coefficient μ_a(p, v, T).

// A table file in the test's temporary directory.
std::string write_table(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("mufric_table_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

// μ_a = 0.1 + 2e-4 p[MPa] + 1e-4 v[m/min] − 5e-5 T[°C], tabulated on a 3 × 2 × 2 grid: trilinear
// interpolation reproduces a law linear in each input exactly anywhere inside, with ∂μ_a/∂p; outside
// the grid it holds the edge value (∂μ_a/∂p = 0 beyond p's range).
TEST(AdhesionTable, InterpolatesALinearLawExactlyAndHoldsItsEdges) {
  auto law = [](double p_mpa, double v_m_min, double t_c) { return 0.1 + 2e-4 * p_mpa + 1e-4 * v_m_min - 5e-5 * t_c; };
  std::string text = "# a law linear in each input\ncontact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu_a\n";
  for (const double p : {1000.0, 200.0, 600.0}) {  // rows in any order
    for (const double v : {10.0, 110.0}) {
      for (const double t : {20.0, 420.0}) text += std::to_string(p) + "," + std::to_string(v) + "," + std::to_string(t) + "," + std::to_string(law(p, v, t)) + "\n";
    }
  }
  const AdhesionTable table = AdhesionTable::read(write_table("linear.csv", text));
  const double mpa = 1e6, m_min = 1.0 / 60.0, kelvin = 273.15;
  for (const auto& [p, v, t] : {std::tuple{350.0, 47.0, 133.0}, {999.0, 10.0, 20.0}, {200.0, 109.0, 400.0}}) {
    const AdhesionTable::Value value = table.at(p * mpa, v * m_min, t + kelvin);
    EXPECT_NEAR(value.mu, law(p, v, t), 1e-6) << p << " MPa, " << v << " m/min, " << t << " C";
    EXPECT_NEAR(value.dmu_dpressure, 2e-4 / mpa, 1e-6 * 2e-4 / mpa);
  }
  const AdhesionTable::Value below = table.at(50.0 * mpa, 5.0 * m_min, 0.0 + kelvin);
  EXPECT_NEAR(below.mu, law(200.0, 10.0, 20.0), 1e-6);
  EXPECT_EQ(below.dmu_dpressure, 0.0);
  EXPECT_NEAR(table.at(3000.0 * mpa, 500.0 * m_min, 900.0 + kelvin).mu, law(1000.0, 110.0, 420.0), 1e-6);
  EXPECT_NE(table.range().find("p 200MPa to 1000MPa"), std::string::npos) << table.range();
}

TEST(AdhesionTable, ErrorsNameTheFileTheLineOrTheMissingGridPoint) {
  const std::string header = "contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu_a\n";
  auto error_of = [](const std::string& path) {
    try {
      AdhesionTable::read(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string missing = write_table("missing.csv", header + "100,10,20,0.1\n200,10,20,0.2\n100,20,20,0.1\n");
  EXPECT_NE(error_of(missing).find("no row for contact_pressure 200MPa, sliding_velocity 20m/min"), std::string::npos)
      << error_of(missing);
  const std::string negative = write_table("negative.csv", header + "100,10,20,0.1\n200,10,20,-0.2\n");
  EXPECT_NE(error_of(negative).find("line 3: mu_a must be >= 0"), std::string::npos) << error_of(negative);
  const std::string repeated = write_table("repeated.csv", header + "100,10,20,0.1\n100,10,20,0.2\n");
  EXPECT_NE(error_of(repeated).find("line 3: repeats the grid point of line 2"), std::string::npos) << error_of(repeated);
  const std::string no_unit = write_table("no_unit.csv", "contact_pressure,sliding_velocity[m/min],temperature[C],mu_a\n1,1,1,0.1\n");
  EXPECT_NE(error_of(no_unit).find("'contact_pressure' has no unit"), std::string::npos) << error_of(no_unit);
  const std::string no_mu = write_table("no_mu.csv", "contact_pressure[MPa],sliding_velocity[m/min],temperature[C]\n1,1,1\n");
  EXPECT_NE(error_of(no_mu).find("mu_a"), std::string::npos) << error_of(no_mu);
}

// A table law whose μ_a rises with pressure, μ_a = 0.2 + 100 p (pressures of order 1e-3 here), at one
// velocity and temperature.
// A table μ_a(p) linear from (0, μ_0) to (p_max, μ_max), at one velocity (1) and temperature (300).
std::shared_ptr<const AdhesionTable> linear_table(double p_max, double mu_0, double mu_max) {
  return std::make_shared<const AdhesionTable>(std::vector<double>{0.0, p_max}, std::vector<double>{1.0},
                                               std::vector<double>{300.0}, std::vector<double>{mu_0, mu_max}, "test");
}

ContactInterface table_law(double tangential) { return with_law(std::make_shared<TableLaw>(linear_table(1e-2, 0.2, 1.2)), tangential); }

// The flat chip slid beyond stick under the table law: τ = μ_a(p) p with μ_a at the point's pressure
// (closed form); the law needs the chip's temperature at the contact before it can shear.
TEST(TableContact, AFlatChipSlidCarriesTheTablesMuTimesP) {
  const double pressure = 1e-3, tangential = 400.0;
  auto [chip, contact] = flat_chip_on_tool(pressure, table_law(tangential));
  solid::SolidProblem& problem = *chip;
  const size_t points = contact->surface_positions().size();
  auto states = std::make_shared<SampledPointStates>(points, 1.0);
  contact->set_point_states(states);
  EXPECT_THROW(contact->commit(Eigen::VectorXd::Zero(problem.dof_count())), Error);  // no temperature yet
  states->set_temperature(std::vector<double>(points, 300.0));
  const Eigen::VectorXd pressed = solid::test::solve_static(problem);
  contact->commit(pressed);
  const double mu_a = 0.2 + 100.0 * pressure;
  Eigen::VectorXd slid = pressed;
  for (Eigen::Index i = 0; i < slid.size(); i += 2) slid(i) += 3.0 * mu_a * pressure / tangential;
  const ContactState s = contact->state(slid);
  for (size_t q = 0; q < s.point_shear.size(); ++q) {
    EXPECT_NEAR(s.point_shear[q], -mu_a * s.point_pressure[q], 1e-9 * pressure) << "x " << s.point_x[q];
  }
  EXPECT_NEAR(std::abs(s.force.x() / s.force.y()), mu_a, 1e-9);
}

// The table law's tangent in slip carries ∂(μ_a(P) P)/∂P = μ_a + P μ_a′: against central differences
// on the rough pair with points in stick and slip.
TEST(TableContact, TangentIsTheExactLinearisationWithAPressureDependentMu) {
  const auto [chip_surface, tool_surface] = rough_surfaces_in_contact();
  solid::SolidProblem problem(solid::IgaSpace(SplineSurface::extruded(chip_surface, -0.5, 2, 3)),
                              std::make_shared<solid::LinearElastic>(1e-2, 0.3, 1.0));
  // Pressures here reach ~0.05: μ_a from 0.1 to 0.6 over them.
  const auto table = linear_table(0.05, 0.1, 0.6);
  auto contact = std::make_shared<MortarContact>(problem.space(), RigidTool{tool_surface}, 50.0, 0,
                                                 with_law(std::make_shared<TableLaw>(table), 50.0));
  uniform_point_states(*contact, 0.0, 300.0);
  problem.add_interaction(contact);
  const Eigen::VectorXd u = committed_then_slid(problem, *contact);
  const StickSlip n =
      count_stick_slip(contact->state(u), [&](size_t, double p) { return table->at(p, 1.0, 300.0).mu * p; });
  ASSERT_GT(n.stick, 3);
  ASSERT_GT(n.slip, 3);
  solid::test::expect_tangent_matches_finite_differences(problem, u, 1.0, "table contact", 1e-5);
}

}  // namespace
}  // namespace mufric::contact
