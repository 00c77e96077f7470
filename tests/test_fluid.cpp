// The lubricant's flow solver against exact and published answers: Couette and Poiseuille flow in
// the periodic channel (in the discrete space: exact to solver tolerance), the same Couette flow
// through traction and Robin sides, Kovasznay flow (exact solution, convergence rates), Ghia et al.'s
// lid-driven cavity, and a uniform flow on a moving mesh (geometric conservation).
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "micro/fluid/cavity.hpp"
#include "micro/fluid/mesh_update.hpp"
#include "micro/fluid/navier_stokes.hpp"

namespace mufric::fluid {
namespace {

// The lubricant of seed 000 Table 2 in a periodic channel of 4 µm × 0.5 µm.
constexpr double kLength = 4e-6, kHeight = 0.5e-6;
const FluidProperties kOil{800.0, 0.032};

BoundaryField constant(const Eigen::Vector2d& value) {
  return [value](const Eigen::Vector2d&, double) { return value; };
}

NavierStokes channel(int nx, int ny, NavierStokesOptions options = {}) {
  options.fluid = kOil;
  return NavierStokes(FluidSpace(rectangle_patch(2, nx, ny, Eigen::Vector2d::Zero(), Eigen::Vector2d(kLength, kHeight), true)),
                      options);
}

// Starts `ns` from the flow whose velocity is `field` at every control point, pressure 0 (a flow in
// the space: linear, so its interpolant is itself).
void start_from(NavierStokes& ns, const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& field) {
  Eigen::VectorXd state = Eigen::VectorXd::Zero(3 * ns.space().node_count());
  for (int a = 0; a < ns.space().node_count(); ++a) state.segment<2>(3 * a) = field(ns.space().node_position(a));
  ns.set_state(state);
}

// Largest deviation of the nodal velocities from a profile u(y) (a linear or quadratic profile is in
// the space, so its control-point values are the profile's interpolant: compare at sample points).
double max_profile_error(const NavierStokes& ns, const std::function<double(double)>& u) {
  double worst = 0.0;
  for (int i = 0; i <= 10; ++i) {
    for (int j = 0; j <= 10; ++j) {
      const double x = kLength * i / 10.0 * 0.999, y = kHeight * j / 10.0;
      const Eigen::Vector2d v = ns.velocity_at(x, y);
      worst = std::max({worst, std::abs(v.x() - u(y)), std::abs(v.y())});
    }
  }
  return worst;
}

TEST(FluidSpace, LinearFieldsHaveTheirGradientAndNoCurvatureOnADistortedMesh) {
  FluidSpace space(rectangle_patch(2, 6, 4, Eigen::Vector2d::Zero(), Eigen::Vector2d(1.0, 1.0), false));
  Eigen::VectorXd d = Eigen::VectorXd::Zero(2 * space.node_count());
  for (int a = 0; a < space.node_count(); ++a) {
    const Eigen::Vector2d x = space.node_position(a);
    d.segment<2>(2 * a) = 0.05 * Eigen::Vector2d(std::sin(3.0 * x.y()) * x.x(), std::cos(2.0 * x.x()) * x.y() * x.y());
  }
  space.set_displacement(d);
  // f = 2 + 3x − 5y is in an isoparametric space on any mesh: nodal values are f at the control points.
  Eigen::VectorXd f(space.node_count());
  for (int a = 0; a < space.node_count(); ++a) f(a) = 2.0 + 3.0 * space.node_position(a).x() - 5.0 * space.node_position(a).y();
  for (int e = 0; e < space.element_count(); e += 5) {
    for (const auto& p : space.element_points(e)) {
      const PhysicalPoint q = space.map(p);
      Eigen::Vector2d gradient = Eigen::Vector2d::Zero();
      Eigen::Vector3d curvature = Eigen::Vector3d::Zero();
      for (size_t a = 0; a < p.nodes.size(); ++a) {
        gradient += f(p.nodes[a]) * q.gradients.col(static_cast<Eigen::Index>(a));
        curvature += f(p.nodes[a]) * q.hessians.col(static_cast<Eigen::Index>(a));
      }
      EXPECT_NEAR(gradient.x(), 3.0, 1e-11);
      EXPECT_NEAR(gradient.y(), -5.0, 1e-11);
      EXPECT_LT(curvature.cwiseAbs().maxCoeff(), 1e-9);
    }
  }
  EXPECT_LT(space.min_relative_jacobian(), 1.0);
  EXPECT_GT(space.min_relative_jacobian(), 0.0);
}

TEST(FluidChannel, CouetteFlowIsExact) {
  NavierStokesOptions o;
  o.pinned_pressure_node = 0;
  NavierStokes ns = channel(8, 4, o);
  const double lid = 2.0;  // m/s
  ns.set_conditions({{Side::bottom, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0},
                     {Side::top, SideConditionKind::velocity, constant(Eigen::Vector2d(lid, 0.0)), {}, 0.0}});
  const FluidStepReport r = ns.solve_steady();
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_LT(max_profile_error(ns, [&](double y) { return lid * y / kHeight; }), 1e-10 * lid);
}

TEST(FluidChannel, CouetteFlowThroughTractionAndRobinSides) {
  // The top wall's shear traction η U/H (and no pressure) drives the same Couette flow; a Robin
  // side α v + σn = h + α g with the exact h and g is satisfied by it for any α.
  const double lid = 2.0, shear = kOil.viscosity * lid / kHeight;
  for (double alpha : {0.0, 1e3, 1e6}) {
    NavierStokes ns = channel(8, 4);
    const SideConditionKind kind = alpha == 0.0 ? SideConditionKind::traction : SideConditionKind::robin;
    ns.set_conditions({{Side::bottom, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0},
                       {Side::top, kind, constant(Eigen::Vector2d(lid, 0.0)), constant(Eigen::Vector2d(shear, 0.0)), alpha}});
    const FluidStepReport r = ns.solve_steady();
    ASSERT_TRUE(r.converged) << r.reason;
    EXPECT_LT(max_profile_error(ns, [&](double y) { return lid * y / kHeight; }), 1e-9 * lid) << "alpha " << alpha;
    EXPECT_LT(std::abs(ns.pressure_at(1e-6, 0.2e-6)), 1e-9 * shear);
    for (const auto& s : ns.side_traction(Side::top)) EXPECT_NEAR(s.traction.x(), shear, 1e-8 * shear);
  }
}

TEST(FluidChannel, ARobinSideWithoutItsWeightIsATractionSide) {
  // Where the Robin weight's share is 0 the wall velocity g no longer acts (a lubricant cavitated off
  // the wall): a wrong g changes nothing, the traction alone drives the exact Couette flow.
  const double lid = 2.0, shear = kOil.viscosity * lid / kHeight;
  NavierStokes ns = channel(8, 4);
  SideCondition top{Side::top, SideConditionKind::robin, constant(Eigen::Vector2d(5.0 * lid, 0.0)),
                    constant(Eigen::Vector2d(shear, 0.0)), 1e6};
  top.robin_share = [](const Eigen::Vector2d&, double) { return 0.0; };
  ns.set_conditions({{Side::bottom, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0}, top});
  const FluidStepReport r = ns.solve_steady();
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_LT(max_profile_error(ns, [&](double y) { return lid * y / kHeight; }), 1e-9 * lid);
  for (const auto& s : ns.robin_traction(Side::top)) EXPECT_NEAR(s.traction.x(), shear, 1e-12 * shear);
}

TEST(FluidChannel, PoiseuilleFlowIsExactAndWallsCarryTheBodyForce) {
  NavierStokesOptions o;
  o.pinned_pressure_node = 0;
  o.body_force = Eigen::Vector2d(1e6, 0.0);  // m/s²: a pressure gradient ρb = 8e8 Pa/m
  NavierStokes ns = channel(8, 4, o);
  ns.set_conditions({{Side::bottom, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0},
                     {Side::top, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0}});
  const FluidStepReport r = ns.solve_steady();
  ASSERT_TRUE(r.converged) << r.reason;
  const double g = kOil.density * o.body_force.x();
  const auto exact = [&](double y) { return g / (2.0 * kOil.viscosity) * y * (kHeight - y); };
  EXPECT_LT(max_profile_error(ns, exact), 1e-10 * exact(kHeight / 2));
  // Each wall takes half the body force: ∫ σn dx = −ρ b H L / 2 on each side (the fluid's view).
  for (Side side : {Side::bottom, Side::top}) {
    double fx = 0.0;
    for (const auto& s : ns.side_traction(side)) fx += s.weight * s.traction.x();
    EXPECT_NEAR(fx, -0.5 * g * kHeight * kLength, 1e-8 * g * kHeight * kLength);
  }
}

// Kovasznay's exact solution (Kovasznay, Proc. Camb. Phil. Soc. 44, 1948) at Re = 40 on
// [−0.5, 1] × [−0.5, 1.5], ρ = 1, η = 1/Re.
struct Kovasznay {
  double re = 40.0;
  double lambda = re / 2.0 - std::sqrt(re * re / 4.0 + 4.0 * std::numbers::pi * std::numbers::pi);
  Eigen::Vector2d velocity(const Eigen::Vector2d& x) const {
    const double e = std::exp(lambda * x.x()), k = 2.0 * std::numbers::pi;
    return {1.0 - e * std::cos(k * x.y()), lambda / k * e * std::sin(k * x.y())};
  }
  double pressure(const Eigen::Vector2d& x) const { return 0.5 * (1.0 - std::exp(2.0 * lambda * x.x())); }
};

struct Errors {
  double velocity = 0.0, pressure = 0.0;
};

Errors kovasznay_errors(int elements) {
  const Kovasznay k;
  NavierStokesOptions o;
  o.fluid = {1.0, 1.0 / k.re};
  o.pinned_pressure_node = 0;
  o.pinned_pressure = k.pressure(Eigen::Vector2d(-0.5, -0.5));
  NavierStokes ns(FluidSpace(rectangle_patch(2, elements, elements + elements / 3, Eigen::Vector2d(-0.5, -0.5),
                                             Eigen::Vector2d(1.0, 1.5), false)), o);
  const BoundaryField exact = [&](const Eigen::Vector2d& x, double) { return k.velocity(x); };
  std::vector<SideCondition> sides;
  for (Side s : {Side::bottom, Side::top, Side::left, Side::right}) sides.push_back({s, SideConditionKind::velocity, exact, {}, 0.0});
  ns.set_conditions(sides);
  const FluidStepReport r = ns.solve_steady();
  EXPECT_TRUE(r.converged) << r.reason;
  // L2 errors; the pressure's up to the constant (its mean difference removed).
  double ev = 0.0, area = 0.0, mean_dp = 0.0;
  for (int e = 0; e < ns.space().element_count(); ++e) {
    for (const auto& p : ns.space().element_points(e)) {
      const PhysicalPoint q = ns.space().map(p);
      ev += q.weight * (ns.velocity(p) - k.velocity(q.position)).squaredNorm();
      mean_dp += q.weight * (ns.pressure(p) - k.pressure(q.position));
      area += q.weight;
    }
  }
  mean_dp /= area;
  double ep = 0.0;
  for (int e = 0; e < ns.space().element_count(); ++e) {
    for (const auto& p : ns.space().element_points(e)) {
      const PhysicalPoint q = ns.space().map(p);
      ep += q.weight * std::pow(ns.pressure(p) - k.pressure(q.position) - mean_dp, 2);
    }
  }
  return {std::sqrt(ev / area), std::sqrt(ep / area)};
}

TEST(FluidVerification, KovasznayErrorsFallAtTheExpectedRates) {
  // Quadratic splines: velocity O(h³) in L2, pressure at least O(h²) (equal order, residual-based
  // stabilisation; Bazilevs et al. 2007 report the same orders).
  const Errors coarse = kovasznay_errors(6), medium = kovasznay_errors(12), fine = kovasznay_errors(24);
  const double rate_v1 = std::log2(coarse.velocity / medium.velocity), rate_v2 = std::log2(medium.velocity / fine.velocity);
  const double rate_p2 = std::log2(medium.pressure / fine.pressure);
  std::cout << "Kovasznay L2 velocity errors " << coarse.velocity << " " << medium.velocity << " " << fine.velocity
            << " (rates " << rate_v1 << ", " << rate_v2 << "); pressure " << coarse.pressure << " " << medium.pressure << " "
            << fine.pressure << " (rate " << rate_p2 << ")\n";
  EXPECT_GT(rate_v2, 2.7);
  EXPECT_GT(rate_p2, 1.8);
  EXPECT_LT(fine.velocity, 1e-3);
}

TEST(FluidVerification, LidDrivenCavityMatchesGhiaAtRe100) {
  const CavityResult r = solve_cavity({100.0, 32, 2});
  ASSERT_TRUE(r.report.converged) << r.report.reason;
  ASSERT_TRUE(r.max_deviation.has_value());
  EXPECT_LT(*r.max_deviation, 0.02);  // per lid speed, both centre lines, all 34 points
  EXPECT_LE(r.report.newton_iterations, 10);
}

// Liquid pumped into the closed channel through its bottom at V (v = (0, V(1 − y/H)), linear, so in
// the space): an incompressible liquid admits no such flow and the step is refused; a compressible one
// compresses uniformly, ∂(ln ρ)/∂t = −∇·v = V/H, so after n backward-Euler steps ln(ρ/ρ₀) = nΔtV/H
// everywhere, and the density law's inverse gives p (closed form): p = K₀ q for a linear density and
// K₀ q / (1 − q b K₀) for Dowson–Higginson's, q = e^(nΔtV/H) − 1. (Convection adds ρV² ≈ 1e-3 Pa
// across the channel, ~1e-7 of it; the two laws differ by ~2e-5 here.)
TEST(FluidChannel, ACompressibleLiquidTakesTheInflowAsUniformCompression) {
  const double speed = 1e-3, dt = 1e-9, bulk = 1.0 / 0.6e-9;  // m/s, s, Pa (Dowson–Higginson's K₀)
  const auto exact = [&](const Eigen::Vector2d& x) { return Eigen::Vector2d(0.0, speed * (1.0 - x.y() / kHeight)); };
  const auto walls = [&](NavierStokes& ns) {
    ns.set_conditions({{Side::bottom, SideConditionKind::velocity, [&](const Eigen::Vector2d& x, double) { return exact(x); }, {}, 0.0},
                       {Side::top, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0}});
    start_from(ns, exact);
  };
  NavierStokes incompressible = channel(6, 4);
  walls(incompressible);
  const FluidStepReport refused = incompressible.step(dt);
  EXPECT_FALSE(refused.converged);
  EXPECT_NE(refused.reason.find("no incompressible flow satisfies it"), std::string::npos) << refused.reason;

  for (const double stiffening : {0.0, 1.7e-9}) {
  NavierStokesOptions o;
  o.fluid = kOil;
  o.fluid.bulk_modulus = bulk;
  o.fluid.pressure_stiffening = stiffening;
  NavierStokes ns(FluidSpace(rectangle_patch(2, 6, 4, Eigen::Vector2d::Zero(), Eigen::Vector2d(kLength, kHeight), true)), o);
  walls(ns);
  for (int n = 1; n <= 3; ++n) {
    const FluidStepReport r = ns.step(dt);
    ASSERT_TRUE(r.converged) << r.reason;
    const double q = std::expm1(n * dt * speed / kHeight);
    const double expected = bulk * q / (1.0 - q * stiffening * bulk);  // ≈ 3 kPa per step
    for (int i = 0; i <= 8; ++i) {
      for (int j = 0; j <= 8; ++j) {
        const double x = kLength * i / 8.0 * 0.999, y = kHeight * j / 8.0;
        EXPECT_NEAR(ns.pressure_at(x, y), expected, 1e-6 * expected) << "b " << stiffening << ", step " << n << " at " << x << ", " << y;
        EXPECT_LT((ns.velocity_at(x, y) - exact(Eigen::Vector2d(x, y))).norm(), 1e-7 * speed);  // Newton tolerance
      }
    }
  }
  }
}

// The same inflow taken by a liquid that leaves the plane: ∇·v = −κ(p − p_a) with v_y = V(1 − y/H)
// gives the uniform p = p_a + V/(κH), steady, and the whole inflow V·L leaves by the leak.
TEST(FluidChannel, ALeakingLiquidTakesTheInflowAtTheLeakPressure) {
  const double speed = 1e-3, dt = 1e-9, ambient = 2e5;  // m/s, s, Pa
  const double leak = speed / (kHeight * 1e4);           // κ, 1/(Pa s): 10 kPa over ambient
  const auto exact = [&](const Eigen::Vector2d& x) { return Eigen::Vector2d(0.0, speed * (1.0 - x.y() / kHeight)); };
  NavierStokes ns = channel(6, 4);
  ns.set_conditions({{Side::bottom, SideConditionKind::velocity, [&](const Eigen::Vector2d& x, double) { return exact(x); }, {}, 0.0},
                     {Side::top, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0}});
  ns.set_leak({[leak](const Eigen::Vector2d&, double) { return leak; }, ambient});
  const double expected = ambient + speed / (leak * kHeight);
  start_from(ns, exact);  // the steady flow from the start
  for (int n = 1; n <= 2; ++n) {
    const FluidStepReport r = ns.step(dt);
    ASSERT_TRUE(r.converged) << r.reason;
    for (int i = 0; i <= 8; ++i) {
      for (int j = 0; j <= 8; ++j) {
        const double x = kLength * i / 8.0 * 0.999, y = kHeight * j / 8.0;
        // The convective term ρ v·∇v ~ ρV²/H, left out of the closed form, is ~1e-9 of the pressure here.
        EXPECT_NEAR(ns.pressure_at(x, y), expected, 1e-6 * (expected - ambient)) << "step " << n << " at " << x << ", " << y;
        EXPECT_LT((ns.velocity_at(x, y) - exact(Eigen::Vector2d(x, y))).norm(), 1e-7 * speed);
      }
    }
    EXPECT_NEAR(ns.leak_rate(), speed * kLength, 1e-6 * speed * kLength);
  }
}

// κ = h²/(6ηL²) against a finite-difference solve of the out-of-plane Reynolds flow it stands for:
// d/dz(h³/(12η) dp/dz) = s h over −L < z < L with p(±L) = 0 and a uniform sink s; κ = s/p(0).
TEST(FluidLeak, TheCoefficientIsTheOutOfPlaneReynoldsFlows) {
  const double film = 0.3e-6, viscosity = 0.032, half_width = 2e-6, sink = 1e6;  // m, Pa s, m, 1/s
  const int n = 400;  // interior nodes of −L < z < L
  const double dz = 2.0 * half_width / (n + 1), conductance = film * film * film / (12.0 * viscosity);
  // −c(p_{i−1} − 2p_i + p_{i+1})/dz² = s h by the Thomas algorithm (tridiagonal Gaussian elimination).
  std::vector<double> diagonal(n, 2.0 * conductance / (dz * dz)), rhs(n, sink * film);
  const double off = -conductance / (dz * dz);
  for (int i = 1; i < n; ++i) {
    const double m = off / diagonal[i - 1];
    diagonal[i] -= m * off;
    rhs[i] -= m * rhs[i - 1];
  }
  std::vector<double> p(n);
  p[n - 1] = rhs[n - 1] / diagonal[n - 1];
  for (int i = n - 2; i >= 0; --i) p[i] = (rhs[i] - off * p[i + 1]) / diagonal[i];
  const double centre = 0.5 * (p[n / 2 - 1] + p[n / 2]);  // z = ±dz/2 around the slice: p(0) − O(dz²)
  EXPECT_NEAR(out_of_plane_leak_coefficient(film, viscosity, half_width), sink / centre, 1e-4 * sink / centre);
  EXPECT_THROW(out_of_plane_leak_coefficient(film, viscosity, 0.0), Error);
}

// The mean-pressure leak moves liquid out of the plane from where p > p̄ to where p < p̄ and keeps the
// volume: a wall that pushes liquid in on one half of the channel and draws it out on the other is
// balanced partly by the flow along the channel and partly out of the plane. Its solution must be the
// ambient leak's with p_a = p̄ (a problem with a unique solution), reached by Newton as fast (the
// rank-one part of the tangent is exact), with ∫κ(p − p̄) = 0.
TEST(FluidLeak, TheMeanPressureLeakIsTheAmbientLeakAtItsOwnMean) {
  const double speed = 1e-3, dt = 1e-9;  // m/s, s
  const double k0 = speed / (kHeight * 1e4);
  const auto kappa = [k0](const Eigen::Vector2d& x, double) { return k0 * (1.0 + 0.5 * std::cos(2.0 * std::numbers::pi * x.x() / kLength)); };
  const auto wall = [speed](const Eigen::Vector2d& x, double) {
    return Eigen::Vector2d(0.0, speed * std::sin(2.0 * std::numbers::pi * x.x() / kLength));
  };
  const auto solve = [&](NavierStokes& ns, PressureLeak leak) {
    ns.set_conditions({{Side::bottom, SideConditionKind::velocity, wall, {}, 0.0},
                       {Side::top, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0}});
    ns.set_leak(std::move(leak));
    return ns.step(dt);
  };
  NavierStokesOptions pinned;
  pinned.pinned_pressure_node = 0;  // the mean leak, like an enclosed fluid, leaves the pressure level free
  NavierStokes mean = channel(8, 4, pinned);
  const FluidStepReport m = solve(mean, {kappa, 0.0, LeakTarget::mean});
  ASSERT_TRUE(m.converged) << m.reason;
  const double target = mean.leak_target_pressure();
  NavierStokes ambient = channel(8, 4);
  const FluidStepReport a = solve(ambient, {kappa, target, LeakTarget::ambient});
  ASSERT_TRUE(a.converged) << a.reason;
  double size = 0.0;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 4; ++j) size = std::max(size, std::abs(ambient.pressure_at(kLength * i / 8.0 * 0.999, kHeight * j / 4.0) - target));
  }
  ASSERT_GT(size, 100.0);  // Pa: the leak carries a real share of the flow
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 4; ++j) {
      const double x = kLength * i / 8.0 * 0.999, y = kHeight * j / 4.0;
      EXPECT_NEAR(mean.pressure_at(x, y), ambient.pressure_at(x, y), 1e-6 * size) << x << ", " << y;
      EXPECT_LT((mean.velocity_at(x, y) - ambient.velocity_at(x, y)).norm(), 1e-6 * speed);
    }
  }
  EXPECT_LE(m.newton_iterations, a.newton_iterations + 1);
  EXPECT_LT(std::abs(mean.leak_rate()), 1e-9 * mean.leak_exchange_rate());
  EXPECT_GT(mean.leak_exchange_rate(), 0.0);
}

TEST(FluidAle, ShearFlowOnAMovingMeshStaysExact) {
  // A steady shear flow v = (a + U y/H, 0) is linear, so it lies in the space however the mesh
  // moves; its nodal values must follow the moving control points exactly, which the backward-Euler
  // ALE step gets right only with the mesh velocity in the convection: (v − w)·∇v (the moving-mesh
  // consistency that a uniform flow alone would not test, since ∇v = 0 there).
  NavierStokesOptions o;
  o.pinned_pressure_node = 0;
  NavierStokes ns = channel(6, 4, o);
  const double slip = 0.7, lid = 2.0;  // m/s
  const auto exact = [&](const Eigen::Vector2d& x) { return Eigen::Vector2d(slip + lid * x.y() / kHeight, 0.0); };
  ns.set_conditions({{Side::bottom, SideConditionKind::velocity, [&](const Eigen::Vector2d& x, double) { return exact(x); }, {}, 0.0},
                     {Side::top, SideConditionKind::velocity, [&](const Eigen::Vector2d& x, double) { return exact(x); }, {}, 0.0}});
  start_from(ns, exact);
  const double dt = 1e-9, shear_stress = kOil.viscosity * lid / kHeight;
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(2 * ns.space().node_count());
  const auto reference = ns.space().patch().points();
  for (int n = 1; n <= 5; ++n) {
    Eigen::VectorXd d(previous.size());
    for (int a = 0; a < ns.space().node_count(); ++a) {
      const double x = reference(a, 0), y = reference(a, 1);
      const double bump = std::sin(2.0 * std::numbers::pi * x / kLength) * std::sin(std::numbers::pi * y / kHeight);
      d.segment<2>(2 * a) = 0.1 * kHeight * std::sin(0.7 * n) * Eigen::Vector2d(0.5 * bump, bump);
    }
    ns.set_mesh(d, (d - previous) / dt);
    previous = d;
    const FluidStepReport r = ns.step(dt);
    ASSERT_TRUE(r.converged) << r.reason;
    EXPECT_GE(r.newton_iterations, 1);
    EXPECT_LT(r.min_relative_jacobian, 1.0);
    for (int a = 0; a < ns.space().node_count(); ++a) {
      EXPECT_LT((ns.state().segment<2>(3 * a) - exact(ns.space().node_position(a))).norm(), 1e-10 * lid);
      EXPECT_LT(std::abs(ns.state()(3 * a + 2)), 1e-8 * shear_stress);
    }
  }
  // Without the mesh velocity the same motion is not followed: the test can tell.
  ns.set_mesh(previous * 1.5, Eigen::VectorXd::Zero(previous.size()));
  ASSERT_TRUE(ns.step(dt).converged);
  double worst = 0.0;
  for (int a = 0; a < ns.space().node_count(); ++a) {
    worst = std::max(worst, (ns.state().segment<2>(3 * a) - exact(ns.space().node_position(a))).norm());
  }
  EXPECT_GT(worst, 1e-4 * lid);
}

TEST(FluidMeshUpdate, RigidBoundaryMotionMovesTheInteriorRigidly) {
  // An infinitesimal rigid motion has no strain: the elastic mesh must follow it exactly, with or
  // without stiffening (the stiffness only weights strain).
  for (double chi : {0.0, 1.0}) {
    FluidSpace space(rectangle_patch(2, 5, 4, Eigen::Vector2d::Zero(), Eigen::Vector2d(2.0, 1.0), false));
    const auto rigid = [](const Eigen::Vector2d& x) { return Eigen::Vector2d(0.1 - 1e-3 * x.y(), -0.05 + 1e-3 * x.x()); };
    std::vector<std::pair<int, Eigen::Vector2d>> prescribed;
    for (Side s : {Side::bottom, Side::top, Side::left, Side::right}) {
      for (int node : space.side_nodes(s)) prescribed.emplace_back(node, rigid(space.node_position(node)));
    }
    MeshUpdate update({chi, 0.3});
    const MeshMoveReport r = update.move(space, prescribed);
    ASSERT_TRUE(r.ok) << r.reason;
    for (int a = 0; a < space.node_count(); ++a) {
      const Eigen::Vector2d x0 = space.patch().points().row(a).transpose();
      EXPECT_LT((space.displacement().segment<2>(2 * a) - rigid(x0)).norm(), 1e-12) << "chi " << chi;
    }
  }
}

double squeeze_mesh_quality(double chi) {
  // The bottom of a periodic channel rises in a bump to 85 % of the gap, in ten increments.
  FluidSpace space(rectangle_patch(2, 16, 6, Eigen::Vector2d::Zero(), Eigen::Vector2d(kLength, kHeight), true));
  MeshUpdate update({chi, 0.3});
  const std::vector<int> bottom = space.side_nodes(Side::bottom), top = space.side_nodes(Side::top);
  double quality = 1.0;
  for (int k = 1; k <= 10; ++k) {
    std::vector<std::pair<int, Eigen::Vector2d>> prescribed;
    for (int node : bottom) {
      const double x = space.patch().points()(node, 0);
      const double bump = std::exp(-std::pow((x - 0.5 * kLength) / (0.1 * kLength), 2));
      prescribed.emplace_back(node, Eigen::Vector2d(0.0, 0.085 * kHeight * bump));
    }
    for (int node : top) prescribed.emplace_back(node, Eigen::Vector2d::Zero());
    const MeshMoveReport r = update.move(space, prescribed);
    if (!r.ok) return r.min_relative_jacobian;
    quality = r.min_relative_jacobian;
  }
  return quality;
}

TEST(FluidMeshUpdate, JacobianStiffeningKeepsTheSqueezedElementsValid) {
  const double plain = squeeze_mesh_quality(0.0), stiffened = squeeze_mesh_quality(1.0);
  std::cout << "min relative det J after the bump: plain elasticity " << plain << ", stiffened " << stiffened << "\n";
  EXPECT_GT(stiffened, 0.05);
  EXPECT_GT(stiffened, plain);
}

// The squeeze film between parallel plates of length B, gap h, the top one approaching at V, both
// ends open to ambient pressure: Reynolds' lubrication theory gives the load per unit depth
// W = η V B³ / h³ (e.g. Hamrock, Fundamentals of Fluid Film Lubrication, 2nd ed. 2004, ch. 10), exact
// up to O(h/B) end effects.
double squeeze_load(const NavierStokes& ns) {
  double load = 0.0;
  for (const auto& s : ns.side_traction(Side::top)) load -= s.weight * s.traction.y();  // the plate receives −σn
  return load;
}

TEST(FluidVerification, SqueezeFilmLoadFollowsReynoldsTheory) {
  const double width = 10e-6, gap = 0.1e-6, approach = 0.5;  // m, m, m/s
  NavierStokesOptions o;
  o.fluid = kOil;
  NavierStokes ns(FluidSpace(rectangle_patch(2, 200, 4, Eigen::Vector2d::Zero(), Eigen::Vector2d(width, gap), false)), o);
  ns.set_conditions({{Side::bottom, SideConditionKind::velocity, constant(Eigen::Vector2d::Zero()), {}, 0.0},
                     {Side::top, SideConditionKind::velocity, constant(Eigen::Vector2d(0.0, -approach)), {}, 0.0}});
  const FluidStepReport r = ns.solve_steady();
  ASSERT_TRUE(r.converged) << r.reason;
  const double reynolds = kOil.viscosity * approach * std::pow(width / gap, 3);
  std::cout << "squeeze film: load / Reynolds theory = " << squeeze_load(ns) / reynolds << " (B/h = 100)\n";
  EXPECT_NEAR(squeeze_load(ns) / reynolds, 1.0, 0.02);

  // The same plate approaching over ten backward-Euler steps on the moving mesh (EMUM): the load
  // follows h⁻³ as the gap closes by 20 %.
  MeshUpdate update;
  const double dt = 0.02 * gap / approach;
  const std::vector<int> top = ns.space().side_nodes(Side::top), bottom = ns.space().side_nodes(Side::bottom);
  Eigen::VectorXd before = ns.space().displacement();
  for (int n = 1; n <= 10; ++n) {
    std::vector<std::pair<int, Eigen::Vector2d>> prescribed;
    for (int node : top) prescribed.emplace_back(node, Eigen::Vector2d(0.0, -approach * dt));
    for (int node : bottom) prescribed.emplace_back(node, Eigen::Vector2d::Zero());
    const MeshMoveReport moved = update.move(ns.space(), prescribed);
    ASSERT_TRUE(moved.ok) << moved.reason;
    const Eigen::VectorXd after = ns.space().displacement();
    ns.set_mesh(after, (after - before) / dt);
    before = after;
    const FluidStepReport step = ns.step(dt);
    ASSERT_TRUE(step.converged) << step.reason;
    const double h = gap - n * approach * dt;
    EXPECT_NEAR(squeeze_load(ns) / (kOil.viscosity * approach * std::pow(width / h, 3)), 1.0, 0.02) << "step " << n;
  }
}

}  // namespace
}  // namespace mufric::fluid
