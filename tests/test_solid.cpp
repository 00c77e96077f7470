// Chip-solver verification, each case against an independent answer: the closed-form Johnson–Cook
// response of a homogeneously stretched element, finite differences of the residual for the
// tangent, exact reproduction of uniform states on distorted patches, Cook's membrane's published
// tip deflection, the generalized-α amplification matrix of Chung & Hulbert, and the closed-form and
// two-period solutions of periodic layers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <thread>

#include "common/error.hpp"
#include "micro/solid/time_integrator.hpp"
#include "micro/spline/profile.hpp"
#include "solid_test_support.hpp"

namespace mufric::solid {
namespace {

using numerics::LinearSolver;
using numerics::LinearSolverKind;
using numerics::MatrixStorage;
using numerics::Side;
using numerics::gauss_legendre;

using test::expect_tangent_matches_finite_differences;
using test::solve_static;

using spline::Points2;
using spline::SplineBasis;
using spline::SplineCurve;
using spline::SplineSurface;

// A bilinear patch through four corners (u along the first pair), elevated and subdivided.
SplineSurface quad_patch(const Eigen::Vector2d& p00, const Eigen::Vector2d& p10, const Eigen::Vector2d& p01,
                         const Eigen::Vector2d& p11, int degree, int spans_u, int spans_v) {
  Points2 p(4, 2);
  p << p00.transpose(), p10.transpose(), p01.transpose(), p11.transpose();
  SplineSurface s(SplineBasis::open_uniform(1, 1, 0, 1), SplineBasis::open_uniform(1, 1, 0, 1), p);
  for (int d = 1; d < degree; ++d) s = s.elevated_u().elevated_v();
  return s.subdivided(spans_u, spans_v);
}

SplineSurface unit_square(int degree, int spans) {
  return quad_patch({0, 0}, {1, 0}, {0, 1}, {1, 1}, degree, spans, spans);
}

// ---- Johnson–Cook: plane-strain isochoric extension, F = diag(λ, 1/λ, 1), log strain e = ln λ.
// With fixed principal axes the exponential-map return map is exactly radial return in log strains:
// τxx − τyy = (2/√3) σy(ε̄p, ε̇̄p, θ) with e = (√3/2) ε̄p + σy/(2√3 G) (plastic, monotonic), and
// ε̇̄p = (2/√3) ė up to the hardening transient (relative 0.2 % of the rate, 1e-4 of the stress).
struct ExtensionRun {
  double tau_difference, plastic_strain, temperature;
};

ExtensionRun stretch_element(const JohnsonCookParameters& jc, double strain_rate, double temperature,
                             double final_log_strain, int steps) {
  const double duration = final_log_strain / strain_rate;
  MaterialState initial;
  initial.temperature = temperature;
  SolidProblem problem(IgaSpace(unit_square(1, 1)), std::make_shared<J2JohnsonCook>(jc), initial);
  for (int node = 0; node < problem.space().node_count(); ++node) {
    const Eigen::Vector2d x = problem.space().node_position(node);
    problem.add_dirichlet({node, 0, x.x(), [=](double t) { return std::exp(strain_rate * t) - 1.0; }});
    problem.add_dirichlet({node, 1, x.y(), [=](double t) { return std::exp(-strain_rate * t) - 1.0; }});
  }
  TimeIntegrationOptions options;
  options.scheme = TimeScheme::quasi_static;
  options.dt = duration / steps;
  options.end_time = duration;
  TimeIntegrator integrator(problem, options);
  const IntegrationReport report = integrator.run();
  EXPECT_TRUE(report.completed) << report.reason;
  const Eigen::Matrix2d f = Eigen::Matrix2d::Identity() + IgaSpace::gradient(problem.space().quadrature()[0], integrator.u());
  const Eigen::Matrix2d tau = integrator.stresses()[0] * f.transpose();  // τ = P Fᵀ
  EXPECT_NEAR(tau(0, 1), 0.0, 1e-6 * tau.norm());
  return {tau(0, 0) - tau(1, 1), problem.states()[0].equivalent_plastic_strain, problem.states()[0].temperature};
}

// ε̄p solving e = (√3/2) ε̄p + σy(ε̄p)/(2√3 G) by bisection, with θ(ε̄p) given.
template <class Theta>
double closed_form_plastic_strain(const JohnsonCookParameters& jc, double shear_modulus, double e, double rate,
                                  Theta theta) {
  double lo = 0.0, hi = 2.0 * e / std::sqrt(3.0);
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    const double residual = std::sqrt(3.0) / 2.0 * mid +
                            johnson_cook_yield_stress(jc, mid, rate, theta(mid)) / (2.0 * std::sqrt(3.0) * shear_modulus) - e;
    (residual > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(JohnsonCook, StretchedElementMatchesTheClosedFormAtSeveralRatesAndTemperatures) {
  JohnsonCookParameters jc;
  jc.heat_fraction = 0.0;  // isothermal here; adiabatic heating has its own test
  const double g = J2JohnsonCook(jc).shear_modulus();
  struct Case {
    double rate, temperature, tolerance;
  };
  // Below ε̇0 the rate term is off and the closed form is exact; above it the rate estimate (2/√3)ė
  // carries the hardening transient (≈1e-4 of the stress).
  for (const Case c : {Case{1e-4, 293.15, 1e-8}, Case{1e-4, 773.15, 1e-8}, Case{1e3, 293.15, 5e-4},
                       Case{1e5, 1173.15, 5e-4}}) {
    const double e = 0.3;
    const ExtensionRun run = stretch_element(jc, c.rate, c.temperature, e, 300);
    const double plastic_rate = 2.0 / std::sqrt(3.0) * c.rate;
    const double eps = closed_form_plastic_strain(jc, g, e, plastic_rate, [&](double) { return c.temperature; });
    const double expected = 2.0 / std::sqrt(3.0) * johnson_cook_yield_stress(jc, eps, plastic_rate, c.temperature);
    EXPECT_NEAR(run.tau_difference, expected, c.tolerance * expected) << "rate " << c.rate << " T " << c.temperature;
    EXPECT_NEAR(run.plastic_strain, eps, 10 * c.tolerance * eps);
  }
}

TEST(JohnsonCook, AdiabaticHeatingMatchesAnIndependentOdeSolution) {
  const JohnsonCookParameters jc;  // Table 1: heat fraction 0.9, c = 450 J/(kg K)
  const double g = J2JohnsonCook(jc).shear_modulus();
  const double rate = 1e3, e = 0.4, theta0 = 293.15;
  const ExtensionRun run = stretch_element(jc, rate, theta0, e, 800);
  const double plastic_rate = 2.0 / std::sqrt(3.0) * rate;
  // dθ/dε̄p = β σy(ε̄p, θ)/(ρ c), classical RK4 with 4000 steps on [0, 0.6].
  const int n = 4000;
  const double h = 0.6 / n;
  std::vector<double> theta(n + 1, theta0);
  auto slope = [&](double eps, double t) {
    return jc.heat_fraction * johnson_cook_yield_stress(jc, eps, plastic_rate, t) / (jc.density * jc.specific_heat);
  };
  for (int k = 0; k < n; ++k) {
    const double x = k * h, t = theta[static_cast<size_t>(k)];
    const double k1 = slope(x, t), k2 = slope(x + h / 2, t + h / 2 * k1), k3 = slope(x + h / 2, t + h / 2 * k2),
                 k4 = slope(x + h, t + h * k3);
    theta[static_cast<size_t>(k) + 1] = t + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  auto theta_at = [&](double eps) {
    const double s = std::clamp(eps / h, 0.0, n - 1e-9);
    const auto k = static_cast<size_t>(s);
    return theta[k] + (s - static_cast<double>(k)) * (theta[k + 1] - theta[k]);
  };
  const double eps = closed_form_plastic_strain(jc, g, e, plastic_rate, theta_at);
  const double expected = 2.0 / std::sqrt(3.0) * johnson_cook_yield_stress(jc, eps, plastic_rate, theta_at(eps));
  EXPECT_GT(run.temperature - theta0, 50.0);  // it did heat up
  EXPECT_NEAR(run.temperature, theta_at(eps), 2e-3 * (theta_at(eps) - theta0));
  EXPECT_NEAR(run.tau_difference, expected, 1e-3 * expected);
}

TEST(JohnsonCook, RateTermNeverLowersTheYieldStressBelowItsReferenceValue) {
  const JohnsonCookParameters jc;
  const double reference = johnson_cook_yield_stress(jc, 0.1, jc.reference_strain_rate, 500.0);
  EXPECT_DOUBLE_EQ(johnson_cook_yield_stress(jc, 0.1, 1e-9, 500.0), reference);
  EXPECT_GT(johnson_cook_yield_stress(jc, 0.1, 10.0, 500.0), reference);
  // Eq. (6): no softening below θ_transition, none left at θ_melt.
  EXPECT_DOUBLE_EQ(johnson_cook_yield_stress(jc, 0.1, 1.0, 250.0), johnson_cook_yield_stress(jc, 0.1, 1.0, 293.15));
  EXPECT_DOUBLE_EQ(johnson_cook_yield_stress(jc, 0.1, 1.0, 1800.0), 0.0);
}

TEST(JohnsonCook, ResidualOnlyUpdateGivesTheSameStressAndState) {
  const J2JohnsonCook material{JohnsonCookParameters()};
  MaterialState start;
  start.temperature = 773.15;
  Eigen::Matrix2d elastic, plastic;
  elastic << 4e-4, 1e-4, -2e-4, -3e-4;
  plastic << 0.05, 0.08, -0.02, -0.04;
  for (const Eigen::Matrix2d& h : {elastic, plastic, Eigen::Matrix2d(1.3 * plastic)}) {
    const StressResponse full = material.update(h, start, 1e-9, true, nullptr), bare = material.update(h, start, 1e-9, false, nullptr);
    ASSERT_TRUE(full.ok && bare.ok);
    EXPECT_LT((full.stress - bare.stress).norm(), 1e-12 * full.stress.norm());
    EXPECT_EQ(full.state.equivalent_plastic_strain, bare.state.equivalent_plastic_strain);
    EXPECT_EQ(full.state.plastic_metric_inverse, bare.state.plastic_metric_inverse);
    EXPECT_EQ(full.state.temperature, bare.state.temperature);
    start = full.state;  // the next, larger stretch loads on from this one's history
  }
  EXPECT_GT(start.equivalent_plastic_strain, 0.0);
}

// ---- Consistent tangent: K w against central differences of f_int, elastic and plastic states.
// The tangent of the displacement formulation and of the mean-dilatation (F-bar) element: each the
// central difference of its own residual. The check multiplies by the stored lower triangle, so an
// element tangent that were not symmetric would fail it too.
void expect_consistent_tangent(VolumetricTreatment volumetric) {
  const auto material = std::make_shared<J2JohnsonCook>(JohnsonCookParameters());
  SolidProblem problem(IgaSpace(quad_patch({0, 0}, {1e-5, 0.1e-5}, {0, 1e-5}, {1.2e-5, 1.1e-5}, 2, 2, 2)), material,
                       MaterialState(), volumetric);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd u(problem.dof_count());
  for (auto& x : u) x = 1e-9 * unit(rng);  // strains ~1e-4: elastic
  expect_tangent_matches_finite_differences(problem, u, 1e-8, "elastic");
  for (auto& x : u) x = 5e-7 * unit(rng);  // strains ~0.1: plastic at every point
  const auto at = problem.assemble(u, 1e-8, false);
  ASSERT_TRUE(at.ok);
  int plastic = 0;
  for (const auto& s : at.states) plastic += s.equivalent_plastic_strain > 0.0;
  EXPECT_EQ(plastic, static_cast<int>(at.states.size()));
  expect_tangent_matches_finite_differences(problem, u, 1e-8, "plastic");
  // And from a committed plastic history (Cp ≠ I, ε̄p > 0), loading on.
  problem.commit(at.states);
  expect_tangent_matches_finite_differences(problem, 1.1 * u, 1e-8, "plastic with history");
}

// Two solvers ordering their patterns at once (draws of a μ measurement side by side) give the
// same bits as one alone. METIS keeps its random state in a global and reseeds it at each ordering:
// orderings made at once drew from one sequence in turns, and the first two draws' μ changed in its
// last digits from run to run (bench/studies/online_learning/README.md, "The scenario through
// Slurm"). A 2D grid's
// Laplacian, where nested dissection competes with AMD, ordered pairwise at once many times.
TEST(LinearSolverThreads, OrderingsMadeAtOnceGiveTheSameSolutionAsOneAlone) {
  constexpr int kSide = 70;
  constexpr int n = kSide * kSide;
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < kSide; ++i) {
    for (int j = 0; j < kSide; ++j) {
      const int k = i * kSide + j;
      entries.emplace_back(k, k, 4.0 + 1e-3 * (k % 7));
      if (i > 0) entries.emplace_back(k, k - kSide, -1.0);
      if (j > 0) entries.emplace_back(k, k - 1, -1.0);
    }
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd b(n);
  for (int k = 0; k < n; ++k) b(k) = std::sin(0.37 * k);
  auto solve = [&] {
    LinearSolver solver(LinearSolverKind::cholesky);
    EXPECT_TRUE(solver.factorize(lower, MatrixStorage::lower_symmetric));
    return Eigen::VectorXd(solver.solve(b));
  };
  const Eigen::VectorXd alone = solve();
  int differing = 0;
  for (int round = 0; round < 12; ++round) {
    Eigen::VectorXd first, second;
    std::thread other([&] { second = solve(); });
    first = solve();
    other.join();
    differing += (first.array() != alone.array()).any() + (second.array() != alone.array()).any();
  }
  EXPECT_EQ(differing, 0) << "solutions that differ from the one solved alone, of 24";
}

TEST(SolidTangent, ConsistentTangentMatchesFiniteDifferencesElasticAndPlastic) {
  expect_consistent_tangent(VolumetricTreatment::full);
}

TEST(SolidTangent, MeanDilatationTangentMatchesFiniteDifferencesElasticAndPlastic) {
  expect_consistent_tangent(VolumetricTreatment::mean_dilatation);
}

// ---- Patch tests: a distorted parameterisation reproduces a uniform state exactly.
SplineSurface distorted_square(unsigned seed) {
  SplineSurface s = unit_square(2, 3);
  Points2 p = s.points();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-0.08, 0.08);
  const int nu = s.u_basis().count(), nv = s.v_basis().count();
  for (int j = 1; j + 1 < nv; ++j) {
    for (int i = 1; i + 1 < nu; ++i) p.row(s.index(i, j)) += Eigen::RowVector2d(unit(rng), unit(rng));
  }
  return SplineSurface(s.u_basis(), s.v_basis(), p);
}

TEST(PatchTest, DistortedPatchReproducesALinearFieldExactly) {
  const auto material = std::make_shared<LinearElastic>(200e9, 0.3, 7800.0);
  SolidProblem problem(IgaSpace(distorted_square(3)), material);
  Eigen::Matrix2d a;
  a << 1e-3, 4e-4, -2e-4, 5e-4;
  const Eigen::Vector2d c(1e-4, -3e-4);
  for (const Side side : {Side::bottom, Side::top, Side::left, Side::right}) {
    for (const int node : problem.space().side_nodes(side)) {
      const Eigen::Vector2d value = a * problem.space().node_position(node) + c;
      problem.add_dirichlet({node, 0, value.x(), {}});
      problem.add_dirichlet({node, 1, value.y(), {}});
    }
  }
  const Eigen::VectorXd u = solve_static(problem);
  for (int node = 0; node < problem.space().node_count(); ++node) {
    const Eigen::Vector2d expected = a * problem.space().node_position(node) + c;
    EXPECT_LT((u.segment<2>(2 * node) - expected).norm(), 1e-14) << "node " << node;
  }
  const Eigen::Matrix2d strain = 0.5 * (a + a.transpose());
  const double lambda = 200e9 * 0.3 / (1.3 * 0.4), mu = 200e9 / 2.6;
  const Eigen::Matrix2d sigma = lambda * strain.trace() * Eigen::Matrix2d::Identity() + 2 * mu * strain;
  for (const auto& s : problem.assemble(u, 1.0, false).stresses) {
    EXPECT_LT((s - sigma).norm(), 1e-9 * sigma.norm());
  }
}

TEST(PatchTest, DistortedPatchUnderUniformTractionHasUniformStress) {
  const auto material = std::make_shared<LinearElastic>(1.0, 0.25, 1.0, PlaneKind::stress);
  SolidProblem problem(IgaSpace(distorted_square(5)), material);
  problem.fix_side(Side::left, 0);  // symmetry planes
  problem.fix_side(Side::bottom, 1);
  problem.add_load({Side::right, Eigen::Vector2d(2.0, 0.0), 0.0, {}});
  problem.add_load({Side::top, Eigen::Vector2d(0.0, -1.0), 0.0, {}});
  const Eigen::VectorXd u = solve_static(problem, LinearSolverKind::cholesky);
  for (const auto& s : problem.assemble(u, 1.0, false).stresses) {
    EXPECT_NEAR(s(0, 0), 2.0, 1e-10);
    EXPECT_NEAR(s(1, 1), -1.0, 1e-10);
    EXPECT_NEAR(s(0, 1), 0.0, 1e-10);
  }
}

// Time-integration options naming the scheme, step, end and tolerance and leaving every callback
// empty (a designated initializer that names only these makes GCC warn of each member it leaves out).
TimeIntegrationOptions integration(TimeScheme scheme, double dt, double end_time, double relative_tolerance) {
  TimeIntegrationOptions options;
  options.scheme = scheme;
  options.dt = dt;
  options.end_time = end_time;
  options.relative_tolerance = relative_tolerance;
  return options;
}

// Both volume treatments: with a uniform J, F̄ = F and the mean-dilatation element is exact too.
class FiniteStrainPatch : public ::testing::TestWithParam<VolumetricTreatment> {};

TEST_P(FiniteStrainPatch, ReproducesAHomogeneousDeformation) {
  const auto material = std::make_shared<J2JohnsonCook>(JohnsonCookParameters());
  SolidProblem problem(IgaSpace(distorted_square(8)), material, MaterialState(), GetParam());
  Eigen::Matrix2d h;
  h << 8e-4, 3e-4, -1e-4, -5e-4;  // elastic, with rotation
  for (const Side side : {Side::bottom, Side::top, Side::left, Side::right}) {
    for (const int node : problem.space().side_nodes(side)) {
      const Eigen::Vector2d value = h * problem.space().node_position(node);
      problem.add_dirichlet({node, 0, value.x(), {}});
      problem.add_dirichlet({node, 1, value.y(), {}});
    }
  }
  TimeIntegrationOptions options;
  options.scheme = TimeScheme::quasi_static;
  options.dt = options.end_time = 1e-6;
  options.relative_tolerance = 1e-12;
  TimeIntegrator integrator(problem, options);
  ASSERT_TRUE(integrator.run().completed);
  for (const auto& q : problem.space().quadrature()) {
    EXPECT_LT((IgaSpace::gradient(q, integrator.u()) - h).norm(), 1e-12);
  }
}

INSTANTIATE_TEST_SUITE_P(PatchTest, FiniteStrainPatch,
                         ::testing::Values(VolumetricTreatment::full, VolumetricTreatment::mean_dilatation));

// ---- A thick-walled cylinder (inner radius a, outer b) under internal pressure, plane strain,
// perfectly plastic and nearly incompressible (ν = 0.4999): Hill, The Mathematical Theory of
// Plasticity (1950), ch. V §3. The plastic zone a ≤ r ≤ c holds p = k (1 − c²/b² + 2 ln(c/a)), and
// an incompressible cylinder moves as u = C/r with C = k c²/(2G) (the elastic zone's σθ − σr =
// 4GC/r² reaches 2k at c), so u(b) = k c²/(2 G b). The quarter annulus is an exact NURBS patch.
// A displacement element with a full quadrature meets one volume constraint per quadrature point
// and locks (Elguedj et al., CMAME 197:2732, 2008, §6); the mean-dilatation element follows Hill.
double cylinder_outer_displacement(VolumetricTreatment volumetric, double pressure_over_k) {
  constexpr double a = 1.0, b = 2.0;
  JohnsonCookParameters jc;
  jc.poisson_ratio = 0.4999;
  jc.b = 0.0;  // perfectly plastic: σy = A
  jc.c = 0.0;
  jc.heat_fraction = 0.0;
  const double k = jc.a / std::sqrt(3.0);
  MaterialState initial;
  initial.temperature = jc.transition_temperature;
  // u: the angle, clockwise from the y axis (a 90° arc, weights 1, √2/2, 1), v: the radius (linear,
  // then elevated); clockwise so that the parameterisation keeps its orientation.
  Points2 p(6, 2);
  p << 0, a, a, a, a, 0, 0, b, b, b, b, 0;
  Eigen::VectorXd w(6);
  w << 1, std::sqrt(0.5), 1, 1, std::sqrt(0.5), 1;
  const SplineSurface quarter =
      SplineSurface(SplineBasis::open_uniform(2, 1, 0, 1), SplineBasis::open_uniform(1, 1, 0, 1), p, w)
          .elevated_v()
          .subdivided(8, 8);
  SolidProblem problem(IgaSpace(quarter), std::make_shared<J2JohnsonCook>(jc), initial, volumetric);
  problem.fix_side(Side::left, 0);   // the y axis
  problem.fix_side(Side::right, 1);  // the x axis
  problem.add_load({Side::bottom, Eigen::Vector2d::Zero(), pressure_over_k * k, [](double t) { return t; }});
  TimeIntegrator integrator(problem, integration(TimeScheme::quasi_static, 0.1, 1.0, 1e-10));
  const IntegrationReport report = integrator.run();
  EXPECT_TRUE(report.completed) << report.reason;
  return problem.space().displacement(integrator.u(), 0.5, 1.0).norm();  // u = ½: 45°; v = 1: r = b
}

TEST(ThickCylinder, MeanDilatationFollowsHillsElasticPlasticSolutionWhereTheFullQuadratureLocks) {
  JohnsonCookParameters jc;
  const double k = jc.a / std::sqrt(3.0), shear = jc.youngs_modulus / (2.0 * 1.4999);
  for (const double c : {1.5, 1.8}) {  // plastic radius; a = 1, b = 2
    const double pressure_over_k = 1.0 - c * c / 4.0 + 2.0 * std::log(c);
    const double hill = k * c * c / (2.0 * shear * 2.0);
    const double mean_dilatation = cylinder_outer_displacement(VolumetricTreatment::mean_dilatation, pressure_over_k);
    const double full = cylinder_outer_displacement(VolumetricTreatment::full, pressure_over_k);
    std::printf("c/a = %.1f, p/k = %.4f: u(b) Hill %.6e, mean dilatation %.6e (%+.2f %%), full %.6e (%+.2f %%)\n", c,
                pressure_over_k, hill, mean_dilatation, 100 * (mean_dilatation / hill - 1), full, 100 * (full / hill - 1));
    EXPECT_NEAR(mean_dilatation / hill, 1.0, 0.01) << "c/a = " << c;
    // The case discriminates: the displacement element is measurably stiffer (−2 % and −6 % here).
    EXPECT_GT(std::abs(full / hill - 1.0), 2.0 * std::abs(mean_dilatation / hill - 1.0)) << "c/a = " << c;
  }
}

// ---- Cook's membrane (Cook 1974; plane stress, E = 1, ν = 1/3, shear load 1 on the right edge):
// the vertical deflection at the middle of the loaded edge, (48, 52), converges to 23.96 (the value
// every benchmark quotes; Q4 elements give 22.08 at 8 × 8, which this solver reproduces at p = 1).
double cooks_membrane_tip(int degree, int spans, LinearSolverKind solver) {
  const auto material = std::make_shared<LinearElastic>(1.0, 1.0 / 3.0, 1.0, PlaneKind::stress);
  SolidProblem problem(IgaSpace(quad_patch({0, 0}, {48, 44}, {0, 44}, {48, 60}, degree, spans, spans)), material);
  problem.fix_side(Side::left, 0);
  problem.fix_side(Side::left, 1);
  problem.add_load({Side::right, Eigen::Vector2d(0.0, 1.0 / 16.0), 0.0, {}});
  return problem.space().displacement(solve_static(problem, solver), 1.0, 0.5).y();  // u = 1, v = ½ is (48, 52)
}

TEST(CooksMembrane, DeflectionConvergesTo2396) {
  double previous_error = 1e9;
  for (const int spans : {2, 4, 8, 16}) {
    const double tip = cooks_membrane_tip(2, spans, LinearSolverKind::lu);
    const double error = std::abs(tip - 23.96);
    EXPECT_LT(error, previous_error) << spans << " spans: " << tip;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.02);  // 16 × 16 quadratic elements
  EXPECT_NEAR(cooks_membrane_tip(1, 8, LinearSolverKind::lu), 22.08, 0.005);  // bilinear = Q4
  EXPECT_NEAR(cooks_membrane_tip(3, 16, LinearSolverKind::cholesky), 23.96, 0.01);
  EXPECT_NEAR(cooks_membrane_tip(2, 8, LinearSolverKind::cholesky), cooks_membrane_tip(2, 8, LinearSolverKind::lu),
              1e-10);
}

// ---- Generalized-α: a fixed–free elastic bar vibrating in its lowest mode. The FE modal
// coordinate follows the scheme's amplification matrix (built here from Chung & Hulbert's
// equations for ü + ω²u = 0) step by step, the period matches the continuum's 4L/c, and energy
// decays exactly as the amplification matrix says (and not at all for ρ∞ = 1).
Eigen::Matrix3d amplification(double omega, double dt, double rho_inf) {
  const double am = (2 * rho_inf - 1) / (rho_inf + 1), af = rho_inf / (rho_inf + 1);
  const double g = 0.5 - am + af, b = 0.25 * (1 - am + af) * (1 - am + af);
  const double w2 = omega * omega;
  const double denominator = (1 - am) + w2 * (1 - af) * b * dt * dt;
  Eigen::RowVector3d a1;  // a_{n+1} in terms of (u, v, a)_n
  a1 << -w2, -w2 * (1 - af) * dt, -(am + w2 * (1 - af) * dt * dt * (0.5 - b));
  a1 /= denominator;
  Eigen::Matrix3d m;
  m.row(0) = Eigen::RowVector3d(1, dt, dt * dt * (0.5 - b)) + b * dt * dt * a1;
  m.row(1) = Eigen::RowVector3d(0, 1, dt * (1 - g)) + g * dt * a1;
  m.row(2) = a1;
  return m;
}

// A Cholesky solver given a symmetric indefinite matrix factorises it by LU instead: the solution
// matches a dense solve, and the fallback is counted; an SPD matrix stays with Cholesky.
TEST(LinearSolverTest, CholeskyHandsAnIndefiniteMatrixToLu) {
  constexpr int n = 40;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  Eigen::MatrixXd spd = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = std::max(0, i - 3); j <= i; ++j) spd(i, j) = spd(j, i) = entry(rng);
    spd(i, i) = 8.0;  // diagonally dominant: positive definite
  }
  Eigen::MatrixXd indefinite = spd;
  indefinite(n / 2, n / 2) = -8.0;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  LinearSolver solver(LinearSolverKind::cholesky);
  ASSERT_TRUE(solver.factorize(spd.sparseView()));
  EXPECT_LT((solver.solve(b) - spd.lu().solve(b)).norm(), 1e-12 * b.norm());
  EXPECT_EQ(solver.lu_fallbacks(), 0);
  ASSERT_TRUE(solver.factorize(indefinite.sparseView())) << solver.reason();
  EXPECT_LT((solver.solve(b) - indefinite.lu().solve(b)).norm(), 1e-12 * b.norm());
  EXPECT_EQ(solver.lu_fallbacks(), 1);
  EXPECT_EQ(solver.analyses(), 1);  // same pattern: one symbolic analysis for both
  // Back to an SPD matrix: Cholesky again, not the stale LU.
  ASSERT_TRUE(solver.factorize((2.0 * spd).sparseView()));
  EXPECT_LT((solver.solve(b) - (2.0 * spd).lu().solve(b)).norm(), 1e-12 * b.norm());
  EXPECT_EQ(solver.lu_fallbacks(), 1);
}

// An unsymmetric matrix given to a Cholesky solver: its symmetric part is factorised and A solved by
// BiCGSTAB with that preconditioner, to the dense LU's answer; a skew part that dominates (the
// iteration cannot converge in its budget) and a symmetric part that is indefinite both go to LU,
// counted, with the same answer.
TEST(LinearSolverTest, AnUnsymmetricMatrixIsSolvedThroughItsSymmetricPartOrByLu) {
  constexpr int n = 60;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  Eigen::MatrixXd spd = Eigen::MatrixXd::Zero(n, n), skew = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = std::max(0, i - 3); j < i; ++j) {
      spd(i, j) = spd(j, i) = entry(rng);
      skew(i, j) = entry(rng);
      skew(j, i) = -skew(i, j);
    }
    spd(i, i) = 8.0;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  LinearSolver solver(LinearSolverKind::cholesky);
  const Eigen::MatrixXd nearly_symmetric = spd + 0.3 * skew;
  ASSERT_TRUE(solver.factorize(nearly_symmetric.sparseView(), MatrixStorage::full, numerics::Symmetry::unsymmetric));
  EXPECT_LT((solver.solve(b) - nearly_symmetric.lu().solve(b)).norm(), 1e-11 * b.norm());
  EXPECT_EQ(solver.lu_fallbacks(), 0);
  EXPECT_GT(solver.krylov_iterations(), 0);
  EXPECT_LE(solver.krylov_iterations(), 10);
  const Eigen::MatrixXd skew_dominated = 0.05 * spd + 200.0 * skew;
  ASSERT_TRUE(solver.factorize(skew_dominated.sparseView(), MatrixStorage::full, numerics::Symmetry::unsymmetric));
  EXPECT_LT((solver.solve(b) - skew_dominated.lu().solve(b)).norm(), 1e-10 * skew_dominated.lu().solve(b).norm());
  EXPECT_EQ(solver.lu_fallbacks(), 1);
  Eigen::MatrixXd indefinite = nearly_symmetric;
  indefinite(n / 2, n / 2) = -8.0;
  ASSERT_TRUE(solver.factorize(indefinite.sparseView(), MatrixStorage::full, numerics::Symmetry::unsymmetric));
  EXPECT_LT((solver.solve(b) - indefinite.lu().solve(b)).norm(), 1e-11 * b.norm());
  EXPECT_EQ(solver.lu_fallbacks(), 2);
  EXPECT_EQ(solver.analyses(), 1);
}

TEST(GeneralizedAlpha, VibratingBarFollowsTheAmplificationMatrixAndKeepsItsPeriod) {
  const double length = 1.0, youngs = 1.0, density = 1.0;
  const auto material = std::make_shared<LinearElastic>(youngs, 0.0, density);
  for (const double rho_inf : {1.0, 0.8, 0.5}) {
    SolidProblem problem(IgaSpace(quad_patch({0, 0}, {length, 0}, {0, 0.05}, {length, 0.05}, 3, 24, 1)), material);
    problem.fix_side(Side::left, 0);
    for (int node = 0; node < problem.space().node_count(); ++node) problem.add_dirichlet({node, 1, 0.0, {}});
    // Lowest discrete mode from the free-dof generalized eigenproblem K φ = ω² M φ.
    const auto k_full = Eigen::MatrixXd(SparseMatrix(problem.assemble(Eigen::VectorXd::Zero(problem.dof_count()), 1.0, true).tangent.selfadjointView<Eigen::Lower>()));
    const auto m_full = Eigen::MatrixXd(SparseMatrix(problem.mass().selfadjointView<Eigen::Lower>()));
    std::vector<int> free;
    for (int i = 0; i < problem.dof_count(); ++i) {
      if (!problem.constrained()[static_cast<size_t>(i)]) free.push_back(i);
    }
    const auto n = static_cast<Eigen::Index>(free.size());
    Eigen::MatrixXd k(n, n), m(n, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index j = 0; j < n; ++j) {
        k(i, j) = k_full(free[static_cast<size_t>(i)], free[static_cast<size_t>(j)]);
        m(i, j) = m_full(free[static_cast<size_t>(i)], free[static_cast<size_t>(j)]);
      }
    }
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eigen(k, m);
    const double omega = std::sqrt(eigen.eigenvalues()(0));
    const double omega_exact = std::numbers::pi / 2 * std::sqrt(youngs / density) / length;
    EXPECT_NEAR(omega, omega_exact, 1e-6 * omega_exact);  // cubic IGA, 24 elements
    Eigen::VectorXd phi = Eigen::VectorXd::Zero(problem.dof_count());
    for (Eigen::Index i = 0; i < n; ++i) phi(free[static_cast<size_t>(i)]) = eigen.eigenvectors()(i, 0);
    const double amplitude = 1e-3 / phi.cwiseAbs().maxCoeff();

    const double period = 2 * std::numbers::pi / omega;
    const int steps_per_period = 40;
    TimeIntegrationOptions options;
    options.spectral_radius = rho_inf;
    options.dt = period / steps_per_period;
    options.end_time = 10 * period;
    options.relative_tolerance = 1e-13;
    TimeIntegrator integrator(problem, options);
    integrator.set_initial(amplitude * phi, Eigen::VectorXd::Zero(problem.dof_count()));
    const Eigen::Matrix3d amp = amplification(omega, options.dt, rho_inf);
    Eigen::Vector3d sdof(amplitude, 0.0, -omega * omega * amplitude);
    const double mphi = phi.dot(problem.mass().selfadjointView<Eigen::Lower>() * phi);
    const auto energy = [&](const Eigen::VectorXd& u, const Eigen::VectorXd& v) {
      return 0.5 * v.dot(problem.mass().selfadjointView<Eigen::Lower>() * v) + problem.elastic_energy(u);
    };
    const double e0 = energy(amplitude * phi, Eigen::VectorXd::Zero(problem.dof_count()));
    double worst = 0.0, previous_q = amplitude, first_crossing = -1.0, last_crossing = -1.0, last_energy = e0;
    int crossings = 0;
    const IntegrationReport report = integrator.run([&](const StepView& s) {
      sdof = amp * sdof;
      const double q = phi.dot(problem.mass().selfadjointView<Eigen::Lower>() * s.u) / mphi;
      worst = std::max(worst, std::abs(q - sdof(0)));
      if (previous_q > 0.0 && q <= 0.0) {  // downward zero crossing, interpolated
        const double t = s.time - options.dt * q / (q - previous_q);
        if (first_crossing < 0.0) first_crossing = t;
        last_crossing = t;
        ++crossings;
      }
      previous_q = q;
      last_energy = energy(s.u, s.v);
    });
    ASSERT_TRUE(report.completed) << report.reason;
    EXPECT_LT(worst, 1e-9 * amplitude) << "rho_inf " << rho_inf;
    const double measured_period = (last_crossing - first_crossing) / (crossings - 1);
    const double exact_period = 2 * std::numbers::pi / omega_exact;
    // Period elongation of the scheme at ωΔt = 2π/40 is below 1 %.
    EXPECT_NEAR(measured_period, exact_period, 0.01 * exact_period) << "rho_inf " << rho_inf;
    // Energy of the SDOF recursion at the same step, from the amplification matrix alone.
    const double predicted = 0.5 * (sdof(1) * sdof(1) + omega * omega * sdof(0) * sdof(0)) * mphi;
    EXPECT_NEAR(last_energy, predicted, 1e-8 * e0) << "rho_inf " << rho_inf;
    if (rho_inf == 1.0) {
      EXPECT_NEAR(last_energy, e0, 1e-9 * e0);
    } else {
      EXPECT_LT(last_energy, e0);
    }
  }
}

// ---- An interaction with an unsymmetric tangent (friction's structure: a shear that follows the
// normal force). Springs on the top nodes push each one down by k u_y and along x by μ k u_y: the
// tangent entry (x, y) lies above the diagonal and has no mirror image, so the tangent must be
// stored full and factorised by LU.
class ShearFollowingNormalSprings : public BoundaryInteraction {
 public:
  // `declares_symmetric`: says its tangent is symmetric whatever it adds (a broken interaction).
  ShearFollowingNormalSprings(std::vector<int> nodes, double stiffness, double ratio, bool declares_symmetric = false)
      : nodes_(std::move(nodes)), stiffness_(stiffness), ratio_(ratio), declares_symmetric_(declares_symmetric) {}
  std::vector<std::vector<int>> coupled_nodes() const override {
    std::vector<std::vector<int>> groups;
    for (const int node : nodes_) groups.push_back({node});
    return groups;
  }
  bool add(const Eigen::VectorXd& u, Eigen::VectorXd& force, TangentAccumulator* tangent, std::string&) const override {
    for (const int node : nodes_) {
      const int x = 2 * node, y = 2 * node + 1;
      force(y) += stiffness_ * u(y);
      force(x) += ratio_ * stiffness_ * u(y);
      if (tangent != nullptr) {
        tangent->add(y, y, stiffness_);
        tangent->add(x, y, ratio_ * stiffness_);
      }
    }
    return true;
  }
  bool symmetric_tangent() const override { return declares_symmetric_; }
  // The same forces as a dense matrix A (force = A u), for the independent solve.
  void add_to(Eigen::MatrixXd& a) const {
    for (const int node : nodes_) {
      a(2 * node + 1, 2 * node + 1) += stiffness_;
      a(2 * node, 2 * node + 1) += ratio_ * stiffness_;
    }
  }

 private:
  std::vector<int> nodes_;
  double stiffness_, ratio_;
  bool declares_symmetric_;
};

SolidProblem loaded_block() {
  SolidProblem problem(IgaSpace(unit_square(2, 4)), std::make_shared<LinearElastic>(200.0, 0.3, 1.0));
  problem.fix_side(Side::bottom, 0);
  problem.fix_side(Side::bottom, 1);
  problem.add_load({Side::top, Eigen::Vector2d(5.0, 0.0), 20.0, {}});
  return problem;
}

std::vector<int> top_nodes(const SolidProblem& problem) {
  std::vector<int> nodes;
  for (int node = 0; node < problem.space().node_count(); ++node) {
    if (problem.space().node_position(node).y() > 1.0 - 1e-12) nodes.push_back(node);
  }
  return nodes;
}

// An interaction that declares a symmetric tangent has its upper triangle dropped; the accumulator
// still checks that what it drops mirrors what it keeps. The springs' (x, y) entry has no mirror
// image: assembling them as symmetric is refused, naming the cause; with ratio 0 (only diagonal
// entries) they are symmetric and assemble; and the frictionless contact's real tangent passes.
TEST(UnsymmetricTangent, AnInteractionThatCallsItsUnsymmetricTangentSymmetricIsRefused) {
  SolidProblem broken = loaded_block();
  broken.add_interaction(std::make_shared<ShearFollowingNormalSprings>(top_nodes(broken), 150.0, 0.4, true));
  ASSERT_EQ(broken.tangent_storage(), MatrixStorage::lower_symmetric);
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(broken.dof_count(), 1e-3);
  try {
    broken.assemble(u, 1.0, true);
    ADD_FAILURE() << "an unsymmetric tangent declared symmetric was assembled";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("declares a symmetric tangent added an unsymmetric one"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(broken.assemble(u, 1.0, false));  // no tangent asked: nothing dropped
  SolidProblem diagonal = loaded_block();
  diagonal.add_interaction(std::make_shared<ShearFollowingNormalSprings>(top_nodes(diagonal), 150.0, 0.0, true));
  EXPECT_TRUE(diagonal.assemble(u, 1.0, true).ok);
}

TEST(UnsymmetricTangent, IsStoredFullAndSolvedByLuToTheDenseSolution) {
  SolidProblem problem = loaded_block();
  const Eigen::MatrixXd k = Eigen::MatrixXd(SparseMatrix(
      problem.assemble(Eigen::VectorXd::Zero(problem.dof_count()), 1.0, true).tangent.selfadjointView<Eigen::Lower>()));
  EXPECT_EQ(problem.tangent_storage(), MatrixStorage::lower_symmetric);
  const auto springs = std::make_shared<ShearFollowingNormalSprings>(top_nodes(problem), 150.0, 0.4);
  ASSERT_EQ(top_nodes(problem).size(), 6u);  // degree 2, 4 spans
  problem.add_interaction(springs);
  EXPECT_EQ(problem.tangent_storage(), MatrixStorage::full);
  EXPECT_EQ(problem.tangent_symmetry(), numerics::Symmetry::unsymmetric);

  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  Eigen::VectorXd u(problem.dof_count());
  for (auto& value : u) value = 1e-3 * normal(rng);
  test::expect_tangent_matches_finite_differences(problem, u, 1.0, "elastic block + unsymmetric springs", 1e-7);

  // The independent answer: (K + A) u = f on the free dofs, dense LU.
  Eigen::MatrixXd system = k;
  springs->add_to(system);
  const Eigen::VectorXd f = problem.external(1.0);
  std::vector<int> free;
  for (int i = 0; i < problem.dof_count(); ++i) {
    if (!problem.constrained()[static_cast<size_t>(i)]) free.push_back(i);
  }
  const auto n = static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd reduced(n, n);
  Eigen::VectorXd rhs(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    rhs(i) = f(free[static_cast<size_t>(i)]);
    for (Eigen::Index j = 0; j < n; ++j) reduced(i, j) = system(free[static_cast<size_t>(i)], free[static_cast<size_t>(j)]);
  }
  const Eigen::VectorXd reference = reduced.partialPivLu().solve(rhs);

  for (const auto kind : {LinearSolverKind::lu, LinearSolverKind::cholesky}) {
    TimeIntegrator integrator(problem, test::static_step_options(kind));
    const IntegrationReport report = integrator.run();
    ASSERT_TRUE(report.completed) << report.reason;
    EXPECT_EQ(report.lu_fallbacks, 0);  // LU directly, or the symmetric part's Cholesky and BiCGSTAB
    ASSERT_EQ(report.steps.size(), 1u);
    if (kind == LinearSolverKind::lu) {
      EXPECT_EQ(report.steps[0].newton_iterations, 1);  // linear, and the tangent is exact
    } else {
      // Inexact Newton: the first solve stops at 1e-2 of the residual (kMaxForcing), so a linear
      // problem takes a few iterations instead of one.
      EXPECT_GT(report.krylov_iterations, 0);
      EXPECT_LE(report.steps[0].newton_iterations, 4);
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      EXPECT_NEAR(integrator.u()(free[static_cast<size_t>(i)]), reference(i), 1e-10 * reference.cwiseAbs().maxCoeff());
    }
  }
}

// Generalised-α adds the mass matrix to the tangent value by value: a full tangent needs the full
// mass with its pattern. A linear problem then converges in one Newton iteration every step.
TEST(UnsymmetricTangent, DynamicStepsAddTheFullMassAndConvergeInOneIteration) {
  SolidProblem problem = loaded_block();
  problem.add_interaction(std::make_shared<ShearFollowingNormalSprings>(top_nodes(problem), 150.0, 0.4));
  const SparseMatrix& lower = problem.mass();
  const SparseMatrix& full = problem.mass(MatrixStorage::full);
  const SparseMatrix tangent = problem.assemble(Eigen::VectorXd::Zero(problem.dof_count()), 1.0, true).tangent;
  EXPECT_EQ(full.nonZeros(), tangent.nonZeros());
  EXPECT_TRUE(std::equal(full.innerIndexPtr(), full.innerIndexPtr() + full.nonZeros(), tangent.innerIndexPtr()));
  EXPECT_DOUBLE_EQ((Eigen::MatrixXd(full) - Eigen::MatrixXd(SparseMatrix(lower.selfadjointView<Eigen::Lower>()))).norm(), 0.0);

  TimeIntegrator integrator(problem, integration(TimeScheme::generalized_alpha, 0.01, 0.05, 1e-12));
  const IntegrationReport report = integrator.run();
  ASSERT_TRUE(report.completed) << report.reason;
  ASSERT_EQ(report.steps.size(), 5u);
  for (const auto& step : report.steps) EXPECT_EQ(step.newton_iterations, 1) << step.time;
}

// ---- Periodic patches.
TEST(Periodicity, FlatPeriodicLayerUnderPressureMatchesTheClosedForm) {
  // Top y = H flat, x control points unevenly spaced (a distorted parameterisation along x).
  const double period = 1e-5, height = 4e-6, pressure = 500e6;
  Points2 top(8, 2);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> unit(-0.2, 0.2);
  for (int i = 0; i < 8; ++i) top.row(i) << period * (i + unit(rng)) / 8, height;
  const SplineCurve curve(SplineBasis::periodic_uniform(3, 8, 0, 1), top, {}, Eigen::Vector2d(period, 0));
  const double youngs = 205e9, nu = 0.29;
  SolidProblem problem(IgaSpace(SplineSurface::extruded(curve, 0.0, 2, 3)),
                       std::make_shared<LinearElastic>(youngs, nu, 7800.0));
  problem.fix_side(Side::bottom, 0);
  problem.fix_side(Side::bottom, 1);
  problem.add_load({Side::top, Eigen::Vector2d::Zero(), pressure, {}});
  const Eigen::VectorXd u = solve_static(problem);
  const double lambda = youngs * nu / ((1 + nu) * (1 - 2 * nu)), mu = youngs / (2 * (1 + nu));
  for (int node = 0; node < problem.space().node_count(); ++node) {
    const double y = problem.space().node_position(node).y();
    EXPECT_NEAR(u(2 * node), 0.0, 1e-12 * height);
    EXPECT_NEAR(u(2 * node + 1), -pressure * y / (lambda + 2 * mu), 1e-12 * height);
  }
}

TEST(Periodicity, OnePeriodEqualsTheSameStructureUnwrappedOverTwoPeriods) {
  spline::RoughnessSpec spec;
  spec.length = 1e-5;
  spec.ra = 0.3e-6;
  spec.correlation_length = 1.5e-6;
  spec.samples = 128;
  const SplineCurve one = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 2, 16).curve;
  // The same profile over two periods: knots and points repeated, period 2 in the parameter.
  std::vector<double> knots = one.basis().knots();
  for (const double t : one.basis().knots()) knots.push_back(t + 1.0);
  Points2 points(32, 2);
  points.topRows(16) = one.points();
  points.bottomRows(16) = one.points().rowwise() + one.shift().transpose();
  const SplineCurve two(SplineBasis::periodic(2, knots, 2.0), points, {}, 2.0 * one.shift());
  auto solve = [&](const SplineCurve& top) {
    auto problem = std::make_unique<SolidProblem>(IgaSpace(SplineSurface::extruded(top, -4e-6, 2, 4)),
                                                  std::make_shared<LinearElastic>(205e9, 0.29, 7800.0));
    problem->fix_side(Side::bottom, 0);
    problem->fix_side(Side::bottom, 1);
    problem->add_load({Side::top, Eigen::Vector2d(150e6, 0.0), 600e6, {}});  // shear and pressure
    Eigen::VectorXd u = solve_static(*problem);
    return std::make_pair(std::move(problem), std::move(u));
  };
  const auto [p1, u1] = solve(one);
  const auto [p2, u2] = solve(two);
  double scale = 0.0, worst = 0.0;
  for (int s = 0; s <= 50; ++s) {
    for (const double v : {0.0, 0.4, 1.0}) {
      const double u = s / 50.0;
      const Eigen::Vector2d d1 = p1->space().displacement(u1, u, v), d2 = p2->space().displacement(u2, u, v);
      const Eigen::Vector2d d2_next = p2->space().displacement(u2, u + 1.0, v);  // the second copy
      scale = std::max(scale, d1.norm());
      worst = std::max({worst, (d1 - d2).norm(), (d1 - d2_next).norm()});
    }
  }
  EXPECT_GT(scale, 1e-9);
  EXPECT_LT(worst, 1e-10 * scale);
}

TEST(ChipPatch, FromConfigurationKeepsTheSurfaceAndHasTheRequestedMesh) {
  spline::RoughnessSpec spec;
  const SplineCurve surface = spline::fit_periodic_profile(spline::synthetic_rough_profile(spec), 2, 20).curve;
  const SplineSurface patch = chip_patch(surface, {.degree = 3, .spans_x = 45, .spans_y = 6, .y_bottom = -4e-6});
  EXPECT_EQ(patch.u_basis().degree(), 3);
  EXPECT_EQ(patch.v_basis().degree(), 3);
  EXPECT_EQ(patch.u_basis().breakpoints().size(), 46u);
  EXPECT_EQ(patch.v_basis().breakpoints().size(), 7u);
  double worst = 0.0;
  for (int s = 0; s <= 500; ++s) worst = std::max(worst, (patch.top().point(s / 500.0) - surface.point(s / 500.0)).norm());
  EXPECT_LT(worst, 1e-18);
  EXPECT_NEAR(patch.point(0.3, 0.0).y(), -4e-6, 1e-20);
  // Degree 1 asked for a quadratic surface: quadratic along x (the geometry is kept exactly), linear
  // across the thickness.
  const SplineSurface mixed = chip_patch(surface, {.degree = 1, .spans_x = 20, .spans_y = 2, .y_bottom = -4e-6});
  EXPECT_EQ(mixed.u_basis().degree(), 2);
  EXPECT_EQ(mixed.v_basis().degree(), 1);
  EXPECT_LT((mixed.top().point(0.37) - surface.point(0.37)).norm(), 1e-18);
  EXPECT_THROW(chip_patch(surface, {.degree = 0}), Error);
  EXPECT_THROW(chip_patch(surface, {.degree = 2, .spans_x = 10}), Error);
}

TEST(TimeIntegration, AFailingStepIsCutBackAndReported) {
  JohnsonCookParameters jc;
  jc.heat_fraction = 0.0;
  const double rate = 1e3;
  auto run = [&](double dt, int max_newton) {
    SolidProblem problem(IgaSpace(unit_square(2, 2)), std::make_shared<J2JohnsonCook>(jc));
    problem.fix_side(Side::bottom, 1);
    problem.fix_side(Side::left, 0);
    for (const int node : problem.space().side_nodes(Side::top)) {
      problem.add_dirichlet({node, 1, -0.2, [=](double t) { return rate * t; }});
    }
    TimeIntegrationOptions options;
    options.scheme = TimeScheme::quasi_static;
    options.dt = dt;
    options.end_time = 1e-3;
    options.max_newton_iterations = max_newton;
    TimeIntegrator integrator(problem, options);
    const IntegrationReport report = integrator.run();
    EXPECT_TRUE(report.completed) << report.reason;
    return std::make_pair(report, integrator.u());
  };
  const auto [coarse, u_coarse] = run(1e-3, 4);  // one step of 20 % compression in ≤ 4 iterations: too much
  EXPECT_FALSE(coarse.cutbacks.empty());
  EXPECT_EQ(coarse.symbolic_analyses, 1);  // every factorisation of the run reused one analysis
  EXPECT_GT(coarse.newton_iterations, 4);
  EXPECT_NE(coarse.cutbacks.front().reason.find("Newton"), std::string::npos) << coarse.cutbacks.front().reason;
  EXPECT_GT(coarse.steps.size(), 1u);
}

// A wall-time limit reaches into the cut-backs: a step that keeps failing stops the run at the
// first failed attempt after should_stop says so, not max_cutbacks attempts later.
TEST(TimeIntegration, AFailingStepStopsWhenAskedBeforeItsCutBacksRunOut) {
  SolidProblem problem(IgaSpace(unit_square(2, 2)), std::make_shared<J2JohnsonCook>(JohnsonCookParameters{}));
  problem.fix_side(Side::bottom, 1);
  problem.fix_side(Side::left, 0);
  TimeIntegrationOptions options;
  options.scheme = TimeScheme::quasi_static;
  options.max_cutbacks = 8;
  int attempts = 0, asked = 0;
  options.coupled_step = [&](TimeIntegrator&, double, double, std::string& reason) {
    ++attempts;
    reason = "never converges";
    return false;
  };
  options.should_stop = [&](std::string& reason) {
    reason = "wall-time limit";
    return ++asked == 3;
  };
  TimeIntegrator integrator(problem, options);
  const IntegrationReport report = integrator.run();
  EXPECT_FALSE(report.completed);
  EXPECT_EQ(attempts, 3);
  EXPECT_EQ(report.cutbacks.size(), 3u);
  EXPECT_NE(report.reason.find("wall-time limit"), std::string::npos) << report.reason;
  options.should_stop = nullptr;  // without it, the cut-backs run out
  attempts = 0;
  TimeIntegrator unlimited(problem, options);
  EXPECT_FALSE(unlimited.run().completed);
  EXPECT_EQ(attempts, options.max_cutbacks + 1);
}

// The step-size control: a linear problem converges in one Newton iteration per step, so each step
// doubles (the growth limit) until max_dt; without max_dt every step keeps the first step's length.
TEST(TimeIntegration, EasyStepsGrowToTheLongestAllowedStepAndNoFurther) {
  auto step_lengths = [](double max_dt) {
    SolidProblem problem(IgaSpace(unit_square(2, 2)), std::make_shared<LinearElastic>(200e9, 0.3, 7800.0));
    problem.fix_side(Side::bottom, 1);
    problem.fix_side(Side::left, 0);
    problem.add_load({Side::top, Eigen::Vector2d::Zero(), 1e8, [](double t) { return t; }});
    TimeIntegrationOptions options;
    options.scheme = TimeScheme::quasi_static;
    options.dt = 1.0;
    options.max_dt = max_dt;
    options.end_time = 20.0;
    TimeIntegrator integrator(problem, options);
    const IntegrationReport report = integrator.run();
    EXPECT_TRUE(report.completed) << report.reason;
    std::vector<double> lengths;
    for (const auto& s : report.steps) {
      EXPECT_LE(s.newton_iterations, 2);
      lengths.push_back(s.dt);
    }
    return lengths;
  };
  EXPECT_EQ(step_lengths(4.0), (std::vector<double>{1, 2, 4, 4, 4, 4, 1}));
  EXPECT_EQ(step_lengths(0.0), std::vector<double>(20, 1.0));
}

}  // namespace
}  // namespace mufric::solid
