// Partitioned coupling on the case that decides the scheme: an enclosed pocket of incompressible
// lubricant under a rigid piston loaded by a pressure (the incompressibility dilemma of Küttler,
// Förster & Wall, Comput. Mech. 38, 2006). The exact answer: the piston cannot move, the pocket keeps
// its volume and its pressure equals the applied one.
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "micro/coupling/cavitation.hpp"
#include "micro/coupling/chip_interface.hpp"
#include "micro/coupling/lubricated_chip.hpp"
#include "micro/coupling/partitioned.hpp"
#include "micro/fluid/mesh_update.hpp"
#include "micro/fluid/navier_stokes.hpp"
#include "micro/solid/time_integrator.hpp"

namespace mufric::coupling {
namespace {

using fluid::Side;

enum class Scheme { dirichlet_neumann, robin_neumann };

// A 2 µm × 1 µm pocket of seed 000's lubricant; the piston is its top side, a 1 µm steel plate
// (7800 kg/m³) pushed down by `applied` Pa, optionally held by a spring (`spring`, Pa per m of its
// travel), integrated by backward Euler like the fluid.
struct PistonPocket {
  static constexpr double kWidth = 2e-6, kHeight = 1e-6, kPlateMassPerArea = 7800.0 * 1e-6;  // kg/m²
  double applied = 1e6;   // Pa
  double dt = 1e-9;       // s
  double spring = 0.0;    // Pa/m
  std::optional<CavitatingFilm> cavitation;  // none: the liquid holds any tension
  std::optional<double> leak;                 // κ, 1/(Pa s), of a liquid leaving the plane toward 0 Pa
  std::vector<double> normal_stress, opening_rate;  // the liquid's σn·n and (g − v)·n at the plate
  Scheme scheme;
  fluid::NavierStokes ns;
  fluid::MeshUpdate mesh;
  Eigen::VectorXd mesh_start;      // fluid mesh displacement at the start of the step
  double piston_start = 0.0, piston_velocity_start = 0.0;  // δ_n, δ̇_n
  std::vector<fluid::NavierStokes::TractionSample> previous_traction;

  static fluid::NavierStokesOptions options(Scheme scheme) {
    fluid::NavierStokesOptions o;
    // All-velocity boundaries leave the pressure level free: Dirichlet–Neumann must pin it.
    if (scheme == Scheme::dirichlet_neumann) o.pinned_pressure_node = 0;
    return o;
  }
  // periodic: the pocket repeats along x instead of having side walls (its top then has no corners,
  // whose wall-fixed test functions leave the Robin traction near them unchecked: an iteration whose
  // fluid fixes its own pressure level, e.g. through a leak, can drift into carrying the plate there).
  explicit PistonPocket(Scheme s, bool periodic = false)
      : scheme(s),
        ns(fluid::FluidSpace(fluid::rectangle_patch(2, 8, 4, Eigen::Vector2d::Zero(), Eigen::Vector2d(kWidth, kHeight), periodic)),
           options(s)) {
    mesh_start = ns.space().displacement();
  }

  // α_R: the plate's inertia per area and step, m/(B Δt), makes the Robin–Neumann iteration of this
  // linear problem nilpotent (the fluid's Robin traction then carries exactly the plate's response);
  // `robin_factor` detunes it. With a spring, the production weight sees it when `spring_in_weight`.
  double robin_factor = 1.0;
  bool spring_in_weight = true;
  double robin_weight() const {
    LubricantOptions o;
    o.chip_mass_per_area = kPlateMassPerArea;
    o.shortest_weight_step = dt;
    o.robin_stiffness = spring_in_weight ? spring : 0.0;
    return robin_factor * coupling::robin_weight(o, dt);
  }

  // Fluid: the piston at δ (interface displacement, 1 value) → the traction σn on the fluid's top
  // side at its Gauss points (x, y per point).
  bool fluid(const Eigen::VectorXd& delta, const Eigen::VectorXd& previous, Eigen::VectorXd& load, std::string& reason) {
    ns.space().set_displacement(mesh_start);
    std::vector<std::pair<int, Eigen::Vector2d>> prescribed;
    for (Side side : {Side::bottom, Side::left, Side::right}) {
      if (!ns.space().has_side(side)) continue;
      for (int node : ns.space().side_nodes(side)) prescribed.emplace_back(node, Eigen::Vector2d::Zero());
    }
    const double move = delta(0) - piston_start;
    for (int node : ns.space().side_nodes(Side::top)) prescribed.emplace_back(node, Eigen::Vector2d(0.0, move));
    const fluid::MeshMoveReport moved = mesh.move(ns.space(), prescribed);
    if (!moved.ok) {
      reason = moved.reason;
      return false;
    }
    ns.set_mesh(ns.space().displacement(), (ns.space().displacement() - mesh_start) / dt);
    const Eigen::Vector2d piston_velocity(0.0, move / dt);
    const fluid::BoundaryField wall = [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); };
    const fluid::BoundaryField piston = [piston_velocity](const Eigen::Vector2d&, double) { return piston_velocity; };
    std::vector<fluid::SideCondition> conditions;
    if (scheme == Scheme::dirichlet_neumann) {
      conditions.push_back({Side::top, fluid::SideConditionKind::velocity, piston, {}, 0.0});
    } else {
      // Robin: α v + σn = α g + h with h the previous iterate's traction at the same Gauss points.
      const Eigen::VectorXd h = previous;
      std::vector<double> parameters;
      for (const auto& p : ns.space().side_points(Side::top)) parameters.push_back(p.u);
      const auto index = [parameters](double t) {
        return static_cast<size_t>(std::lower_bound(parameters.begin(), parameters.end(), t - 1e-15) - parameters.begin());
      };
      const fluid::BoundaryField traction = [h, index](const Eigen::Vector2d&, double t) {
        return Eigen::Vector2d(h.segment<2>(2 * static_cast<Eigen::Index>(index(t))));
      };
      const CavitatingFilm* cavities = cavitation ? &*cavitation : nullptr;
      const fluid::BoundaryScalar follows = [cavities, index](const Eigen::Vector2d&, double t) {
        return cavities != nullptr && cavities->cavitated(index(t)) ? 0.0 : 1.0;
      };
      conditions.push_back({Side::top, fluid::SideConditionKind::robin, piston, traction, robin_weight(), follows});
    }
    for (Side side : {Side::left, Side::right, Side::bottom}) {
      if (ns.space().has_side(side)) conditions.push_back({side, fluid::SideConditionKind::velocity, wall, {}, 0.0});
    }
    ns.set_conditions(conditions);
    if (leak) ns.set_leak({[k = *leak](const Eigen::Vector2d&, double) { return k; }, 0.0});
    const fluid::FluidStepReport r = ns.solve_step(dt);
    if (!r.converged) {
      reason = r.reason;
      return false;
    }
    auto samples = scheme == Scheme::robin_neumann ? ns.robin_traction(Side::top) : ns.side_traction(Side::top);
    normal_stress.resize(samples.size());
    opening_rate.resize(samples.size());
    for (size_t i = 0; i < samples.size(); ++i) {
      normal_stress[i] = samples[i].traction.dot(samples[i].normal);
      opening_rate[i] = (piston_velocity - samples[i].velocity).dot(samples[i].normal);
      if (cavitation && cavitation->cavitated(i)) samples[i].traction = -cavitation->cavitation_pressure() * samples[i].normal;
    }
    load.resize(2 * static_cast<Eigen::Index>(samples.size()));
    for (size_t i = 0; i < samples.size(); ++i) load.segment<2>(2 * static_cast<Eigen::Index>(i)) = samples[i].traction;
    return true;
  }

  // Structure: the fluid's traction → the piston's new position (backward Euler on m δ̈ = F − p B).
  bool structure(const Eigen::VectorXd& load, Eigen::VectorXd& delta, std::string&) const {
    double fluid_force = 0.0;  // upward, per unit depth: the plate receives −σn
    const auto& points = ns.space().side_points(Side::top);
    for (size_t i = 0; i < points.size(); ++i) {
      const fluid::PhysicalPoint q = ns.space().map(points[i], &kTop);
      fluid_force -= q.weight * load(2 * static_cast<Eigen::Index>(i) + 1);
    }
    // m (v − v_n)/Δt = F − p B − k B δ with δ = δ_n + Δt v.
    const double mass = kPlateMassPerArea * kWidth, stiffness = spring * kWidth;
    const double velocity = (mass * piston_velocity_start + dt * (fluid_force - applied * kWidth - stiffness * piston_start)) /
                            (mass + stiffness * dt * dt);
    delta = Eigen::VectorXd::Constant(1, piston_start + dt * velocity);
    return true;
  }
  static constexpr Side kTop = Side::top;

  struct Outcome {
    bool converged = true;
    std::string reason;
    int iterations = 0;
    std::vector<double> first_step_load_residuals;
    double piston = 0.0, pressure = 0.0, area = 0.0;
    double piston_velocity = 0.0;  // m/s, in the last step
  };

  Outcome run(int steps, const CouplingOptions& options) {
    InterfaceAccelerator accelerator(options);
    const PartitionedSolvers solvers{
        [this](const Eigen::VectorXd& load, Eigen::VectorXd& d, std::string& why) { return structure(load, d, why); },
        [this](const Eigen::VectorXd& d, const Eigen::VectorXd& load, Eigen::VectorXd& new_load, std::string& why) {
          return fluid(d, load, new_load, why);
        },
        {}, {}};  // the piston's pocket is checked after the run
    Outcome out;
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(1);
    Eigen::VectorXd load = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(ns.space().side_points(Side::top).size()));
    for (int n = 0; n < steps; ++n) {
      ns.begin_step();
      mesh_start = ns.space().displacement();
      const CouplingStepReport r = coupled_step(solvers, load, delta, accelerator, options);
      out.iterations += r.iterations;
      if (n == 0) out.first_step_load_residuals = r.load_residuals;
      if (!r.converged) {
        out.converged = false;
        out.reason = r.reason;
        return out;
      }
      // The accepted step: the fluid is re-solved at the converged interface, the piston advances.
      std::string why;
      Eigen::VectorXd final_load;
      EXPECT_TRUE(fluid(delta, load, final_load, why)) << why;
      piston_velocity_start = (delta(0) - piston_start) / dt;
      piston_start = delta(0);
      if (cavitation) {  // the film's state for the next step
        std::vector<FilmSample> film;
        for (size_t i = 0; i < normal_stress.size(); ++i) {
          const double width = kWidth / static_cast<double>(normal_stress.size());
          film.push_back({kHeight + piston_start, width, width, false, normal_stress[i], opening_rate[i]});
        }
        cavitation->update(film, dt);
      }
    }
    out.piston = piston_start;
    out.piston_velocity = piston_velocity_start;
    out.pressure = ns.pressure_at(0.5 * kWidth, 0.5 * kHeight);
    out.area = ns.space().area();
    return out;
  }
};

CouplingOptions options(Acceleration a) {
  CouplingOptions o;
  o.acceleration = a;
  o.relaxation = 0.5;
  o.max_iterations = 100;
  return o;
}

TEST(EnclosedPocket, RobinNeumannHoldsThePistonAtTheAppliedPressure) {
  PistonPocket pocket(Scheme::robin_neumann);
  const double area = pocket.ns.space().area();
  const auto out = pocket.run(5, options(Acceleration::iqn_ils));
  ASSERT_TRUE(out.converged) << out.reason;
  std::cout << "Robin-Neumann + IQN-ILS: " << out.iterations << " exchanges over 5 steps, piston " << out.piston
            << " m, pocket pressure " << out.pressure << " Pa (applied " << pocket.applied << ")\n";
  EXPECT_NEAR(out.pressure / pocket.applied, 1.0, 1e-6);
  EXPECT_NEAR(out.area / area, 1.0, 1e-9);   // the pocket keeps its volume
  EXPECT_LT(std::abs(out.piston), 1e-9 * PistonPocket::kHeight);
}

// A pocket whose liquid leaves the plane (∇·v = −κp) lets the piston sink at W = κ p H with
// p = P − 2ηW/H (the plate's balance with the film's normal viscous stress); backward Euler reaches
// that rate within a few steps (the plate's inertia decays by (m/BΔt)/(m/BΔt + 1/κH) = 0.07 per step),
// and the pocket's lost area is the leak's to the coupling's tolerance.
TEST(EnclosedPocket, ALeakingPocketLetsThePistonSinkAtTheLeakRate) {
  PistonPocket pocket(Scheme::robin_neumann, true);
  pocket.leak = 0.01;  // 1/(Pa s): W ≈ 1 cm/s under 1 MPa
  const double area = pocket.ns.space().area();
  const auto out = pocket.run(6, options(Acceleration::iqn_ils));
  ASSERT_TRUE(out.converged) << out.reason;
  const double height = PistonPocket::kHeight + out.piston, viscosity = fluid::FluidProperties{}.viscosity;
  const double sink_rate = *pocket.leak * height * pocket.applied / (1.0 + 2.0 * viscosity * *pocket.leak);
  EXPECT_NEAR(-out.piston_velocity / sink_rate, 1.0, 1e-3);
  EXPECT_NEAR(out.pressure / (pocket.applied - 2.0 * viscosity * sink_rate / height), 1.0, 1e-3);
  EXPECT_NEAR((area - out.area) / (-out.piston * PistonPocket::kWidth), 1.0, 1e-6);  // the columns' area
  EXPECT_NEAR(pocket.ns.leak_rate() / (-out.piston_velocity * PistonPocket::kWidth), 1.0, 1e-3);
}

// A chip pressed on the tool resists the film by its stiffness more than by its inertia. With the plate
// on a spring the structure's step is (m/(BΔt) + kΔt) v = −σn + …, a Robin relation of its own: with
// α_R equal to it (robin_weight with robin_stiffness = k) plain Robin–Neumann is exact after one
// exchange; with the inertia alone each exchange leaves 1 − α_R/(m/(BΔt) + kΔt) of the error
// (the closed form of the iteration on this linear problem, the pocket held still).
TEST(EnclosedPocket, TheRobinWeightWithTheStructuresStiffnessMakesRobinNeumannExact) {
  CouplingOptions plain = options(Acceleration::constant_relaxation);
  plain.relaxation = 1.0;  // the Robin condition alone, nothing accelerating it
  const double k = 7.8e15;  // Pa/m: kΔt = m/(BΔt) at Δt = 1 ns, so the inertia-only weight leaves half
  PistonPocket tuned(Scheme::robin_neumann), inertia(Scheme::robin_neumann);
  tuned.spring = inertia.spring = k;
  inertia.spring_in_weight = false;
  const auto with_spring = tuned.run(3, plain);
  const auto without = inertia.run(3, plain);
  ASSERT_TRUE(with_spring.converged) << with_spring.reason;
  ASSERT_TRUE(without.converged) << without.reason;
  std::cout << "spring-held plate, plain Robin-Neumann: " << with_spring.iterations << " exchanges over 3 steps with "
            << "alpha_R = m/(B dt) + k dt, " << without.iterations << " with m/(B dt)\n";
  EXPECT_LE(with_spring.iterations, 3 * 3);  // per step: the exact traction, then the displacement settles
  EXPECT_NEAR(with_spring.pressure / tuned.applied, 1.0, 1e-6);
  EXPECT_NEAR(without.pressure / inertia.applied, 1.0, 1e-6);
  const double expected_factor = k * tuned.dt / (PistonPocket::kPlateMassPerArea / tuned.dt + k * tuned.dt);
  const auto& r = without.first_step_load_residuals;
  ASSERT_GE(r.size(), 4U);
  for (size_t i = 1; i + 1 < 4; ++i) EXPECT_NEAR(r[i + 1] / r[i], expected_factor, 0.02) << "exchange " << i + 1;
}

TEST(EnclosedPocket, APulledPistonIsHeldByTensionUnlessTheFilmCavitates) {
  // Without cavitation the liquid holds the plate at any tension. With it, the first step still
  // holds (states change between steps), the film then cavitates, and the plate flies against the
  // cavitation pressure alone: backward Euler from rest under the constant net force B (p_c − p_applied)
  // gives δ_n = Δt² a (n − 1) n / 2 after n steps, a = B (p_c − p_applied)/m; the liquid stays at rest,
  // so the cavity is B δ_n.
  PistonPocket holding(Scheme::robin_neumann);
  holding.applied = -1e6;
  const auto held = holding.run(5, options(Acceleration::iqn_ils));
  ASSERT_TRUE(held.converged) << held.reason;
  EXPECT_NEAR(held.pressure / holding.applied, 1.0, 1e-6);
  EXPECT_LT(std::abs(held.piston), 1e-9 * PistonPocket::kHeight);
  for (double p_c : {0.0, -0.5e6}) {
    PistonPocket pocket(Scheme::robin_neumann);
    pocket.applied = -1e6;
    pocket.cavitation.emplace(p_c);
    const int steps = 5;
    const auto out = pocket.run(steps, options(Acceleration::iqn_ils));
    ASSERT_TRUE(out.converged) << out.reason;
    const double mass = PistonPocket::kPlateMassPerArea * PistonPocket::kWidth;
    const double a = PistonPocket::kWidth * (p_c - pocket.applied) / mass;
    const double expected = pocket.dt * pocket.dt * a * (steps - 1) * steps / 2.0;
    std::cout << "pulled plate, p_c = " << p_c << " Pa: " << out.iterations << " exchanges, moved " << out.piston
              << " m (flight against p_c: " << expected << "), cavity " << pocket.cavitation->cavity_area() << " m^2/m\n";
    EXPECT_NEAR(out.piston / expected, 1.0, 1e-6);
    EXPECT_TRUE(pocket.cavitation->cavitated(0));
    EXPECT_NEAR(pocket.cavitation->cavity_area() / (PistonPocket::kWidth * expected), 1.0, 1e-6);
    EXPECT_NEAR(pocket.cavitation->cavitated_fraction(), 1.0, 1e-12);
    if (p_c != 0.0) continue;
    // Pushed back, the plate closes the cavity and the film refills once the plate is back at the
    // liquid: from then on the liquid holds the plate again.
    pocket.applied = 4e6;
    const auto back = pocket.run(12, options(Acceleration::iqn_ils));
    ASSERT_TRUE(back.converged) << back.reason;
    EXPECT_FALSE(pocket.cavitation->cavitated(0));
    EXPECT_EQ(pocket.cavitation->cavity_area(), 0.0);
    const double refilled_at = back.piston;
    const auto still = pocket.run(3, options(Acceleration::iqn_ils));
    ASSERT_TRUE(still.converged) << still.reason;
    std::cout << "pushed back: refilled at " << refilled_at << " m, then " << still.piston << " m, pocket pressure "
              << still.pressure << " Pa\n";
    EXPECT_LT(refilled_at, 0.0);  // the space shrank past the liquid's
    EXPECT_NEAR(still.piston, refilled_at, 1e-9 * PistonPocket::kHeight);
    EXPECT_NEAR(still.pressure / pocket.applied, 1.0, 1e-3);
  }
  // A pushed plate's film never cavitates.
  PistonPocket pushed(Scheme::robin_neumann);
  pushed.cavitation.emplace(0.0);
  const auto out = pushed.run(5, options(Acceleration::iqn_ils));
  ASSERT_TRUE(out.converged) << out.reason;
  EXPECT_FALSE(pushed.cavitation->cavitated(0));
  EXPECT_NEAR(out.pressure / pushed.applied, 1.0, 1e-6);
  EXPECT_LT(std::abs(out.piston), 1e-9 * PistonPocket::kHeight);
}

TEST(Pockets, RunsBetweenSpotsWrapAroundThePeriod) {
  // Spots at 2 and 5 of 7 samples: pockets {3, 4} and {6, 0, 1} (across the period's end).
  std::vector<FilmSample> film(7, FilmSample{1e-7, 1e-6, 1e-6, false, 0.0, 0.0});
  EXPECT_EQ(pocket_runs(film).size(), 1u);
  film[2].spot = film[5].spot = true;
  const auto runs = pocket_runs(film);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0], (std::vector<size_t>{3, 4}));
  EXPECT_EQ(runs[1], (std::vector<size_t>{6, 0, 1}));
}

// A spot run is wetted, whole, when liquid touches the wall at one of its two edges (brute force over
// the cases): spots {2, 3} between pockets 1 and 4, spot {6} between 5 and 0 (across the period's end).
TEST(Pockets, ASpotIsWettedWhenLiquidHoldsAtOneOfItsEdges) {
  std::vector<FilmSample> film(7, FilmSample{1e-7, 1e-6, 1e-6, false, 0.0, 0.0});
  film[2].spot = film[3].spot = film[6].spot = true;
  const std::vector<char> none(7, 0);
  EXPECT_EQ(wetted_spots(film, none), none);  // no liquid at any edge
  for (size_t liquid = 0; liquid < 7; ++liquid) {
    std::vector<char> at_wall(7, 0);
    at_wall[liquid] = 1;
    const std::vector<char> wetted = wetted_spots(film, at_wall);
    const bool first_run = liquid == 1 || liquid == 4, second_run = liquid == 5 || liquid == 0;
    EXPECT_EQ(wetted, (std::vector<char>{0, 0, first_run, first_run, 0, 0, second_run})) << "liquid at " << liquid;
  }
  // Liquid deep inside a pocket but not at its edges wets nothing: pockets of two samples each side.
  std::vector<FilmSample> wide(8, FilmSample{1e-7, 1e-6, 1e-6, false, 0.0, 0.0});
  wide[0].spot = wide[4].spot = true;
  std::vector<char> inside(8, 0);
  inside[2] = inside[6] = 1;
  EXPECT_EQ(wetted_spots(wide, inside), std::vector<char>(8, 0));
  // Without pockets there is no edge; and a flag per sample is required.
  std::vector<FilmSample> all_spot(3, FilmSample{1e-9, 1e-6, 1e-6, true, 0.0, 0.0});
  EXPECT_EQ(wetted_spots(all_spot, std::vector<char>(3, 1)), std::vector<char>(3, 0));
  EXPECT_THROW(wetted_spots(film, std::vector<char>(6, 1)), Error);
}

TEST(CavitatingFilm, TheLiquidThatRunsPastAClosingCavityFillsTheNearestCavities) {
  // Five samples of 1 µm; samples 0 and 3 are spots, formed as cavities of 2 and 3 nm (× 1 µm). In
  // 1 ns the wall at sample 0 comes back 3 nm: its cavity closes, and 1 nm × 1 µm of liquid ran on
  // past the wall; the nearest cavity, sample 3 (two samples away across the period's end, 0 → 4 → 3),
  // takes it, so the cavities together shrink by exactly the 3 nm × 1 µm the wall moved in.
  const double width = 1e-6;
  std::vector<FilmSample> film(5, FilmSample{1e-7, width, width, false, -1e5, 0.0});
  film[0].spot = film[3].spot = true;
  film[0].film = 2e-9, film[3].film = 3e-9;
  CavitatingFilm cavitation(0.0);
  cavitation.form(film);
  EXPECT_NEAR(cavitation.cavity_area(), 5e-9 * width, 1e-27);
  film[0].opening_rate = -3.0;  // m/s for 1 ns: the wall comes 3 nm back onto 2 nm of cavity
  film[1].opening_rate = 0.5;   // a full sample: its wall's motion changes the film, not the cavities
  cavitation.update(film, 1e-9);
  EXPECT_FALSE(cavitation.cavitated(0));
  EXPECT_TRUE(cavitation.cavitated(3));
  EXPECT_NEAR(cavitation.closing_overshoot(), 1e-9 * width, 1e-27);
  EXPECT_EQ(cavitation.lost_overshoot(), 0.0);
  // The cavities lost the 3 nm the closing wall moved in: 2 at sample 0, 1 at sample 3.
  EXPECT_NEAR(cavitation.cavity_area(), 2e-9 * width, 1e-27);
  // With no cavity left to take it, the excess is lost, and said.
  film[3].opening_rate = -2.5;  // 2 nm of cavity, 2.5 nm of wall
  cavitation.update(film, 1e-9);
  EXPECT_EQ(cavitation.cavity_area(), 0.0);
  EXPECT_NEAR(cavitation.lost_overshoot(), 0.5e-9 * width, 1e-27);
}

// A leaking film's cavity fills at most its column's gap: a spot of 3 nm whose wall leaves the liquid
// by 5 nm keeps a 3 nm cavity and reports the 2 nm it cut; a sealed film's books take the 5 nm.
TEST(CavitatingFilm, ALeakingFilmsCavityFillsAtMostItsGap) {
  const double width = 1e-6;
  std::vector<FilmSample> film(3, FilmSample{1e-7, width, width, false, -1e5, 0.0});
  film[1].spot = true;
  film[1].film = 3e-9;
  for (const bool within_gap : {true, false}) {
    CavitatingFilm cavitation(0.0, within_gap);
    cavitation.form(film);
    film[1].opening_rate = 2.0;  // m/s for 1 ns: the wall leaves the (gone) liquid by 2 nm more
    cavitation.update(film, 1e-9);
    EXPECT_TRUE(cavitation.cavitated(1));
    EXPECT_NEAR(cavitation.cavity_area(), (within_gap ? 3e-9 : 5e-9) * width, 1e-27);
    EXPECT_NEAR(cavitation.overgrowth(), (within_gap ? 2e-9 : 0.0) * width, 1e-27);
    film[1].opening_rate = 0.0;
  }
}

TEST(CavitatingFilm, ACavityOpensWhereTheLiquidPullsAndClosesWhenTheWallReturns) {
  // Sample 0 pulls (σn·n = 0.1 MPa > −p_c = 0), sample 1 pushes; each stands for 1 µm.
  std::vector<FilmSample> film{{1e-7, 1e-6, 1e-6, false, 1e5, 0.0}, {1e-7, 1e-6, 1e-6, false, -1e5, 0.0}};
  CavitatingFilm cavitation(0.0);
  cavitation.update(film, 1e-9);
  EXPECT_TRUE(cavitation.cavitated(0));
  EXPECT_FALSE(cavitation.cavitated(1));
  EXPECT_EQ(cavitation.cavity_area(), 0.0);  // it opens from the next step on
  EXPECT_NEAR(cavitation.cavitated_fraction(), 0.5, 1e-15);
  // The wall leaves the liquid at 2 m/s for 3 ns, then comes back at 1 m/s: the cavity is 6 nm
  // thick, then 5, 4, …, and the sample refills in the step that brings it to zero.
  film[0].opening_rate = 2.0;
  for (int k = 0; k < 3; ++k) cavitation.update(film, 1e-9);
  EXPECT_NEAR(cavitation.cavity_area(), 6e-9 * 1e-6, 1e-24);
  film[0].opening_rate = -1.0;
  for (int k = 0; k < 5; ++k) cavitation.update(film, 1e-9);
  EXPECT_TRUE(cavitation.cavitated(0));
  EXPECT_NEAR(cavitation.cavity_area(), 1e-9 * 1e-6, 1e-24);
  cavitation.update(film, 1e-9);
  EXPECT_FALSE(cavitation.cavitated(0));
  EXPECT_EQ(cavitation.cavity_area(), 0.0);
  // A new film's contact spots hold no liquid: cavities as large as the layer (20 nm thick across x)
  // that close only when the chip has come that layer's thickness along the wall's normal nearer the
  // liquid. The spot's wall is sloped (1.25 µm of wall over 1 µm of x, a 3-4-5 slope): the layer is
  // 16 nm thick along the normal, and a cavity of thickness c takes c × 1.25 µm of area.
  std::vector<FilmSample> formed{{20e-9, 1e-6, 1.25e-6, true, 0.0, 0.0}, {1e-7, 1e-6, 1e-6, false, 0.0, 0.0}};
  CavitatingFilm fresh(0.0);
  fresh.form(formed);
  EXPECT_TRUE(fresh.cavitated(0));
  EXPECT_FALSE(fresh.cavitated(1));
  EXPECT_NEAR(fresh.cavity_area(), 20e-9 * 1e-6, 1e-27);
  EXPECT_NEAR(fresh.cavitated_fraction(), 1.25 / 2.25, 1e-15);
  formed[0].opening_rate = -10.0;  // m/s toward the liquid, for 1 ns: 10 nm
  fresh.update(formed, 1e-9);
  EXPECT_TRUE(fresh.cavitated(0));
  EXPECT_NEAR(fresh.cavity_area(), 6e-9 * 1.25e-6, 1e-27);
  fresh.update(formed, 1e-9);
  EXPECT_FALSE(fresh.cavitated(0));
  // A lower cavitation pressure (the liquid holds 0.2 MPa of tension) keeps both samples full.
  CavitatingFilm strong(-2e5);
  film[0].normal_stress = 1e5;
  strong.update(film, 1e-9);
  EXPECT_FALSE(strong.cavitated(0));
}

TEST(EnclosedPocket, DirichletNeumannFailsOnTheEnclosedPocket) {
  PistonPocket pocket(Scheme::dirichlet_neumann);
  const auto out = pocket.run(5, options(Acceleration::iqn_ils));
  std::cout << "Dirichlet-Neumann: " << (out.converged ? "converged" : "failed: " + out.reason) << "\n";
  EXPECT_FALSE(out.converged);
}

TEST(EnclosedPocket, QuasiNewtonNeedsFewerExchangesThanRelaxation) {
  // With the Robin weight tuned to the plate (factor 1) and detuned by 10× either way.
  for (double factor : {1.0, 0.1, 10.0}) {
    PistonPocket relaxed(Scheme::robin_neumann), aitken(Scheme::robin_neumann), iqn(Scheme::robin_neumann);
    relaxed.robin_factor = aitken.robin_factor = iqn.robin_factor = factor;
    const auto r = relaxed.run(5, options(Acceleration::constant_relaxation));
    const auto a = aitken.run(5, options(Acceleration::aitken));
    const auto q = iqn.run(5, options(Acceleration::iqn_ils));
    ASSERT_TRUE(q.converged) << q.reason;
    std::cout << "alpha_R x " << factor << ", exchanges over 5 steps: constant relaxation (0.5) "
              << (r.converged ? std::to_string(r.iterations) : "failed: " + r.reason) << ", Aitken "
              << (a.converged ? std::to_string(a.iterations) : "failed: " + a.reason) << ", IQN-ILS " << q.iterations << "\n";
    EXPECT_NEAR(q.pressure / iqn.applied, 1.0, 1e-6);
    if (r.converged) {
      EXPECT_LT(q.iterations, r.iterations) << "alpha_R x " << factor;
    }
  }
}

// A periodic curve over [0, L) through (Greville x, f(x)): a smooth rough surface for the tests.
spline::SplineCurve periodic_curve(int degree, int n, double length, const std::function<double(double)>& f) {
  const spline::SplineBasis b = spline::SplineBasis::periodic_uniform(degree, n, 0.0, length);
  spline::Points2 p(n, 2);
  for (int i = 0; i < n; ++i) {
    const double x = b.greville_abscissa(i);
    p.row(i) = Eigen::RowVector2d(x, f(x));
  }
  return spline::SplineCurve(b, p, {}, Eigen::Vector2d(length, 0.0));
}

constexpr double kInterval = 10e-6;
double chip_height(double x) { return 0.2e-6 * std::sin(2 * std::numbers::pi * x / kInterval) + 0.05e-6 * std::cos(6 * std::numbers::pi * x / kInterval); }
double tool_height(double x) { return 0.22e-6 + 0.1e-6 * std::sin(4 * std::numbers::pi * x / kInterval + 0.3); }

TEST(ChipInterface, GraphParameterIsFoundAcrossPeriods) {
  const spline::SplineCurve c = periodic_curve(3, 24, kInterval, chip_height);
  const PeriodicGraph g([&](double t) { return c.point(t); }, 0.0, kInterval, 64);
  for (double x : {-13.1e-6, -0.2e-6, 0.0, 3.7e-6, 9.99e-6, 25.3e-6}) {
    const double t = g.parameter_at(x);
    EXPECT_NEAR(c.point(t).x(), x, 1e-12 * kInterval) << x;
  }
}

TEST(ChipInterface, AFoldedCurveIsSeenFromAboveByItsUpperEnvelope) {
  // x(t) = t + 0.25 L sin(2πt/L) turns back (dx/dt = 1 + π/2 cos < 0 near t = L/2): over part of the
  // period three points share an x. The brute-force answer: every sign change of x(t) − x0 on 20 000
  // samples, bisected, the highest point kept.
  const double period = kInterval, pi = std::numbers::pi;
  const auto point = [&](double t) {
    return Eigen::Vector2d(t + 0.25 * period * std::sin(2 * pi * t / period),
                           0.1 * period * std::cos(2 * pi * t / period) + 0.05 * period * std::sin(4 * pi * t / period));
  };
  const PeriodicGraph g(point, 0.0, period, 64);
  EXPECT_TRUE(g.folded());
  int folded_points = 0;
  for (double x0 : {-3.3e-6, 0.7e-6, 4.6e-6, 4.9e-6, 5.2e-6, 5.45e-6, 6.2e-6, 9.5e-6, 14.8e-6}) {  // the fold: 4.47–5.53 µm
    const double xr = x0 - std::floor(x0 / period) * period;
    double best_y = -1e300, best_x = 0.0;
    int roots = 0;
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
      double a = period * k / n, b = period * (k + 1) / n;
      if ((point(a).x() - xr) * (point(b).x() - xr) > 0.0) continue;
      ++roots;
      for (int i = 0; i < 60; ++i) {
        const double m = 0.5 * (a + b);
        ((point(a).x() - xr) * (point(m).x() - xr) <= 0.0 ? b : a) = m;
      }
      if (point(a).y() > best_y) best_y = point(a).y(), best_x = point(a).x();
    }
    folded_points += roots > 1 ? 1 : 0;
    const double t = g.parameter_at(x0);
    EXPECT_NEAR(point(t).x() - (x0 - xr), best_x, 1e-12 * period) << x0;
    EXPECT_NEAR(g.height_at(x0), best_y, 1e-9 * period) << x0;
  }
  EXPECT_GE(folded_points, 2);  // the check went through the fold
}

TEST(ChipInterface, AFoldsTipRampsTheFilmFloorInsteadOfJumping) {
  // A lip curled forward (x(t) turns back as above, its tip at x = 0.5526 L on top: the upper envelope
  // steps there by 0.178 L, found by brute force over 200 000 samples), carried along x by δ — a chip
  // sliding under a fixed column at x0. The ramped floor must not jump: between neighbouring δ it
  // changes as a slope does, in proportion to the step.
  const double period = kInterval, pi = std::numbers::pi, x0 = 3.0e-6;
  const auto shape = [&](double t) {
    return Eigen::Vector2d(t + 0.25 * period * std::sin(2 * pi * t / period),
                           -0.1 * period * std::cos(2 * pi * t / period) + 0.05 * period * std::sin(2 * pi * t / period));
  };
  const int steps = 4000;
  const double sweep = 4e-6, step = sweep / steps;  // the tip (x ≈ 5.53 µm) passes x0 at δ ≈ −2.5 µm
  double largest_jump = 0.0, largest_ramped_change = 0.0, previous_height = 0.0, previous_ramped = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const double delta = -4.5e-6 + k * step;
    const PeriodicGraph g([&](double t) { return Eigen::Vector2d(shape(t) + Eigen::Vector2d(delta, 0.0)); }, 0.0, period, 256);
    const double height = g.height_at(x0), ramped = g.ramped_height_at(x0, kFilmFloorMaxSlope);
    EXPECT_GE(ramped, height);
    if (k > 0) {
      largest_jump = std::max(largest_jump, std::abs(height - previous_height));
      largest_ramped_change = std::max(largest_ramped_change, std::abs(ramped - previous_ramped));
    }
    previous_height = height, previous_ramped = ramped;
  }
  EXPECT_GT(largest_jump, 0.15 * period);             // the envelope's cliff crossed x0
  EXPECT_LT(largest_ramped_change, 200.0 * step);     // the floor moved as a slope, not a cliff
}

TEST(ChipInterface, AGraphGentlerThanTheRampKeepsItsHeight) {
  const spline::SplineCurve c = periodic_curve(3, 24, kInterval, chip_height);  // slopes below 0.25
  const PeriodicGraph g([&](double t) { return c.point(t); }, 0.0, kInterval, 256);
  for (int k = 0; k <= 100; ++k) {
    const double x = -2e-6 + 14e-6 * k / 100;
    EXPECT_NEAR(g.ramped_height_at(x, kFilmFloorMaxSlope), g.height_at(x), 1e-15) << x;
  }
}

TEST(ChipInterface, LoadsMoveToTheChipConservatively) {
  const spline::SplineCurve surface = periodic_curve(2, 32, kInterval, chip_height);
  const solid::IgaSpace chip(solid::chip_patch(surface, {.degree = 2, .spans_x = 32, .spans_y = 4, .y_bottom = -2e-6}));
  ChipSurface s(chip);
  // The chip slid by 3.3 µm and deformed smoothly.
  Eigen::VectorXd u(chip.dof_count());
  for (int a = 0; a < chip.node_count(); ++a) {
    const Eigen::Vector2d x = chip.node_position(a);
    u.segment<2>(2 * a) = Eigen::Vector2d(3.3e-6 + 0.05e-6 * std::sin(2 * std::numbers::pi * x.x() / kInterval),
                                          0.03e-6 * std::cos(2 * std::numbers::pi * x.x() / kInterval) * (x.y() + 2e-6) / 2e-6);
  }
  s.update(u, Eigen::VectorXd::Zero(chip.dof_count()));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Vector2d> positions, tractions;
  std::vector<double> weights;
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (int q = 0; q < 200; ++q) {
    const double x = -kInterval + 3 * kInterval * uniform(rng);
    positions.emplace_back(x, 0.0);
    tractions.emplace_back(1e8 * (uniform(rng) - 0.5), -1e9 * uniform(rng));
    weights.push_back(1e-8 * uniform(rng));
    total += weights.back() * tractions.back();
    // The parameter found lies under the point: the chip surface passes through x there.
    EXPECT_NEAR(s.position(s.parameter_at(x)).x(), x, 1e-12 * kInterval);
  }
  const Eigen::VectorXd f = s.nodal_forces(positions, tractions, weights);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int a = 0; a < chip.node_count(); ++a) sum += f.segment<2>(2 * a);
  EXPECT_LT((sum - total).norm(), 1e-14 * total.norm());
  // Only the surface's control points are loaded.
  const auto top = chip.side_nodes(numerics::Side::top);
  for (int a = 0; a < chip.node_count(); ++a) {
    if (std::find(top.begin(), top.end(), a) == top.end()) {
      EXPECT_EQ(f.segment<2>(2 * a).norm(), 0.0);
    }
  }
}

TEST(ChipInterface, FilmMeshFollowsTheChipAndKeepsItsMinimumThickness) {
  const spline::SplineCurve chip_curve = periodic_curve(2, 32, kInterval, chip_height);
  const spline::SplineCurve tool_curve = periodic_curve(3, 32, kInterval, tool_height);
  const PeriodicGraph chip([&](double t) { return chip_curve.point(t); }, 0.0, kInterval, 256);
  const PeriodicGraph tool([&](double t) { return tool_curve.point(t); }, 0.0, kInterval, 256);
  GapMeshOptions o;
  o.elements_x = 48;
  o.min_film = 5e-9;
  const spline::SplineSurface patch = gap_patch(chip, tool, 0.0, o);
  // The bottom row interpolates the chip at the columns.
  const Eigen::MatrixX2d rows = gap_boundary_rows(patch, chip, tool, o);
  const int nu = patch.u_basis().count();
  for (int i = 0; i < nu; ++i) {
    const double x = rows(i, 0);
    EXPECT_NEAR(patch.point(x, 0.0).y(), chip.height_at(x), 1e-15);
    EXPECT_NEAR(rows(i, 1), patch.points()(i, 1), 1e-18);
  }
  // Between the columns it stays close to the chip; the film never thins below min_film; the
  // parameterisation is x(u, ·) = u.
  double worst = 0.0, thinnest = 1.0;
  for (int k = 0; k < 1000; ++k) {
    const double x = kInterval * (k + 0.5) / 1000;
    worst = std::max(worst, std::abs(patch.point(x, 0.0).y() - chip.height_at(x)));
    thinnest = std::min(thinnest, patch.point(x, 1.0).y() - patch.point(x, 0.0).y());
    EXPECT_NEAR(patch.point(x, 0.5).x(), x, 1e-15);
  }
  std::cout << "film mesh: largest distance to the chip between columns " << worst << " m, thinnest film " << thinnest << " m\n";
  EXPECT_LT(worst, 2e-9);
  EXPECT_GE(thinnest, o.min_film * (1 - 1e-12));
  EXPECT_LT(thinnest, 2 * o.min_film);  // the tool dips into the chip here: the film is at its minimum
}

// The film's net moved onto a chip that turns into steep walls (slopes up to 5, as a ploughed lip's)
// by the algebraic column motion: never folds on the way, and ends where a film built from scratch on
// that chip starts (an independent construction: gap_patch).
TEST(ChipInterface, TheFilmsColumnNetFollowsASteepeningChipWithoutFolding) {
  const auto steep = [](double x) { return 0.2e-6 * std::tanh(40.0 * std::sin(2 * std::numbers::pi * x / kInterval)); };
  const spline::SplineCurve tool_curve = periodic_curve(3, 32, kInterval, tool_height);
  const PeriodicGraph tool([&](double t) { return tool_curve.point(t); }, 0.0, kInterval, 256);
  const auto chip_at = [&](double fraction) {
    return periodic_curve(2, 64, kInterval, [&](double x) { return (1 - fraction) * chip_height(x) + fraction * steep(x); });
  };
  GapMeshOptions o;
  o.elements_x = 64;
  o.min_film = 20e-9;
  const spline::SplineCurve start_curve = chip_at(0.0);
  const PeriodicGraph start([&](double t) { return start_curve.point(t); }, 0.0, kInterval, 512);
  fluid::FluidSpace space(gap_patch(start, tool, 0.0, o));
  double lowest = 1.0;
  Eigen::MatrixX2d net;
  for (int k = 1; k <= 10; ++k) {
    const spline::SplineCurve curve = chip_at(0.1 * k);
    const PeriodicGraph chip([&](double t) { return curve.point(t); }, 0.0, kInterval, 512);
    net = gap_net(space.patch(), gap_boundary_rows(space.patch(), chip, tool, o));
    Eigen::VectorXd displacement(2 * space.node_count());
    for (int a = 0; a < space.node_count(); ++a) displacement.segment<2>(2 * a) = (net.row(a) - space.patch().points().row(a)).transpose();
    space.set_displacement(displacement);
    lowest = std::min(lowest, space.min_relative_jacobian());
  }
  std::cout << "smallest relative Jacobian on the way to the steep chip: " << lowest << "\n";
  EXPECT_GT(lowest, 0.0);
  const spline::SplineCurve end_curve = chip_at(1.0);
  const PeriodicGraph end([&](double t) { return end_curve.point(t); }, 0.0, kInterval, 512);
  const spline::SplineSurface fresh = gap_patch(end, tool, 0.0, o);
  EXPECT_LT((net - fresh.points()).cwiseAbs().maxCoeff(), 1e-18);
}

// A scalar interface for coupled_step by plain relaxation (ω = 1): the structure returns the load as
// its displacement (so the displacement criterion is not the one tested), the fluid maps it by `map`.
struct ScalarInterface {
  CouplingOptions options;
  std::function<double(double)> map;
  std::function<double()> kinematic;  // optional
  double solvable_load = std::numeric_limits<double>::infinity();  // the structure fails beyond |λ| > this
  int exchanges = 0;
  double converged_load = 0.0;  // the step's load on return
  ScalarInterface(double relative_tolerance, int max_iterations) {
    options.acceleration = Acceleration::constant_relaxation;
    options.relaxation = 1.0;
    options.relative_tolerance = relative_tolerance;
    options.load_tolerance = 0.0;
    options.displacement_tolerance = 1.0;
    options.max_iterations = max_iterations;
  }
  CouplingStepReport run() {
    exchanges = 0;
    const PartitionedSolvers solvers{
        [this](const Eigen::VectorXd& load, Eigen::VectorXd& d, std::string& why) {
          if (std::abs(load(0)) > solvable_load) {
            why = "load out of reach";
            return false;
          }
          d = load;
          return true;
        },
        [this](const Eigen::VectorXd& d, const Eigen::VectorXd&, Eigen::VectorXd& next, std::string&) {
          ++exchanges;
          next = Eigen::VectorXd::Constant(1, map(d(0)));
          return true;
        },
        kinematic, {}};
    InterfaceAccelerator accelerator(options);
    Eigen::VectorXd start = Eigen::VectorXd::Zero(1), d = Eigen::VectorXd::Zero(1);
    const CouplingStepReport report = coupled_step(solvers, start, d, accelerator, options);
    converged_load = start(0);
    return report;
  }
};

// λ = 1 + λ/2 (fixed point 2), the residual halving each exchange. With a kinematic residual reported
// (here 10⁻ᵏ at exchange k), the step also waits for it: the load alone converges at exchange 10
// (|λ̃ − λ| = 2⁻⁹ < 1e-3 λ̃, λ̃ ≈ 2), a kinematic tolerance of 1e-12 holds it to exchange 12, and with
// 1e-25 the step runs out of its 20 exchanges.
TEST(CoupledStep, AReportedKinematicResidualMustAlsoConverge) {
  ScalarInterface scalar(1e-3, 20);
  scalar.map = [](double load) { return 1.0 + 0.5 * load; };
  scalar.kinematic = [&scalar] { return std::pow(10.0, -scalar.exchanges); };
  const auto run = [&](double kinematic_tolerance) {
    scalar.options.kinematic_tolerance = kinematic_tolerance;
    return scalar.run();
  };
  const CouplingStepReport loose = run(1.0);
  ASSERT_TRUE(loose.converged);
  EXPECT_EQ(loose.iterations, 10);
  const CouplingStepReport tight = run(1e-12);
  ASSERT_TRUE(tight.converged);
  EXPECT_EQ(tight.iterations, 12);
  ASSERT_EQ(tight.kinematic_residuals.size(), 12u);
  EXPECT_DOUBLE_EQ(tight.kinematic_residuals.back(), 1e-12);
  EXPECT_FALSE(run(1e-25).converged);
}

// A step whose load change stops falling fails after stall_iterations exchanges without a new best,
// where a slowly but steadily contracting one runs to convergence. λ̃ = 1 − ρλ: the change |λ̃ − λ| is
// multiplied by ρ each exchange (the closed form of this scalar iteration), so ρ = 0.9 converges in
// ~90 exchanges and ρ = 1 (an oscillation of constant size) never improves.
TEST(CoupledStep, AStalledIterationFailsEarlyAndASlowOneConverges) {
  ScalarInterface scalar(1e-4, 500);
  scalar.options.stall_iterations = 6;
  double rho = 0.0;
  scalar.map = [&rho](double load) { return 1.0 - rho * load; };
  const auto run = [&](double contraction) {
    rho = contraction;
    return scalar.run();
  };
  const CouplingStepReport slow = run(0.9);
  ASSERT_TRUE(slow.converged) << slow.reason;
  EXPECT_GT(slow.iterations, 50);
  const CouplingStepReport stalled = run(1.0);
  EXPECT_FALSE(stalled.converged);
  EXPECT_EQ(stalled.iterations, 1 + scalar.options.stall_iterations);  // the best is the first; six more without a better one
  EXPECT_NE(stalled.reason.find("stalled"), std::string::npos) << stalled.reason;
  EXPECT_TRUE(is_interface_failure(stalled.reason)) << stalled.reason;
  scalar.options.stall_iterations = 0;  // off: the oscillation runs to max_iterations
  const CouplingStepReport exhausted = run(1.0);
  EXPECT_EQ(exhausted.iterations, scalar.options.max_iterations);
  EXPECT_TRUE(is_interface_failure(exhausted.reason)) << exhausted.reason;
}

// n independent copies of λ̃ = 1 + λ/2 from λ = 0 by plain relaxation: each component's change is
// 2^(1−k) at exchange k (closed form), the load's |λ̃ − λ| = √n 2^(1−k). A floor of 2⁻⁶ Pa on the root
// mean square is met at exchange 7 whatever n; a floor on the plain norm would need 7 + log₂√n (11 for n = 100).
TEST(CoupledStep, TheLoadFloorIsARootMeanSquareOverTheComponents) {
  const auto exchanges_for = [](Eigen::Index components) {
    CouplingOptions options;
    options.acceleration = Acceleration::constant_relaxation;
    options.relaxation = 1.0;
    options.relative_tolerance = 0.0;
    options.load_tolerance = 1.01 * std::ldexp(1.0, -6);  // just above 2⁻⁶, so that rounding cannot decide the exchange
    options.displacement_tolerance = 1.0;
    options.max_iterations = 40;
    const PartitionedSolvers solvers{
        [](const Eigen::VectorXd& load, Eigen::VectorXd& d, std::string&) { return d = load, true; },
        [](const Eigen::VectorXd&, const Eigen::VectorXd& load, Eigen::VectorXd& next, std::string&) {
          next = (1.0 + 0.5 * load.array()).matrix();
          return true;
        },
        {}, {}};
    InterfaceAccelerator accelerator(options);
    Eigen::VectorXd load = Eigen::VectorXd::Zero(components), d = Eigen::VectorXd::Zero(components);
    const CouplingStepReport report = coupled_step(solvers, load, d, accelerator, options);
    EXPECT_TRUE(report.converged) << report.reason;
    return report.iterations;
  };
  EXPECT_EQ(exchanges_for(1), 7);
  EXPECT_EQ(exchanges_for(100), 7);
}

// Two load components: the first λ̃ = 1 + λ/2 (converges, as above), the second λ̃ = 1 − λ (an
// oscillation of constant size 1 under plain relaxation: it never converges). A share of 0 on the
// second — a film's traction over a contact spot, which the chip never receives — leaves the first to
// decide: 2^(1−k) ≤ 1e-3 |λ̃| (λ̃ → 2) at k = 10. Shared by both, the step runs out of its exchanges.
TEST(CoupledStep, TheLoadConvergesOnTheShareThatReachesTheStructure) {
  const auto run = [](const Eigen::VectorXd& share) {
    CouplingOptions options;
    options.acceleration = Acceleration::constant_relaxation;
    options.relaxation = 1.0;
    options.relative_tolerance = 1e-3;
    options.load_tolerance = 0.0;
    options.displacement_tolerance = 1.0;
    options.max_iterations = 30;
    PartitionedSolvers solvers{
        [](const Eigen::VectorXd& load, Eigen::VectorXd& d, std::string&) { return d = load, true; },
        [](const Eigen::VectorXd&, const Eigen::VectorXd& load, Eigen::VectorXd& next, std::string&) {
          next.resize(2);
          next << 1.0 + 0.5 * load(0), 1.0 - load(1);
          return true;
        },
        {}, {}};
    if (share.size() != 0) solvers.load_share = [share] { return share; };
    InterfaceAccelerator accelerator(options);
    Eigen::VectorXd load = Eigen::VectorXd::Zero(2), d = Eigen::VectorXd::Zero(2);
    return coupled_step(solvers, load, d, accelerator, options);
  };
  const CouplingStepReport first_only = run(Eigen::Vector2d(1.0, 0.0));
  ASSERT_TRUE(first_only.converged) << first_only.reason;
  EXPECT_EQ(first_only.iterations, 10);
  EXPECT_FALSE(run(Eigen::VectorXd()).converged);
  EXPECT_FALSE(run(Eigen::Vector2d(1.0, 1.0)).converged);
  EXPECT_THROW(run(Eigen::VectorXd::Ones(3)), Error);
}

// A solver failing on an iterate restarts the step from the last solved iterate with half the
// relaxation. λ̃ = 1 − 2λ (fixed point 1/3): with ω = 1 the iterates are 0, 1, −1, 3 (the change grows
// by −2 each exchange) and the structure fails at λ = 3 (beyond 1.5). Restarted from λ = −1 (image 3)
// with ω = 1/2, the error is multiplied by 1 − 3ω = −1/2 per exchange and the step converges to 1/3.
TEST(CoupledStep, ASolverFailureRestartsFromTheLastSolvedIterate) {
  ScalarInterface scalar(1e-10, 200);
  scalar.map = [](double load) { return 1.0 - 2.0 * load; };
  scalar.solvable_load = 1.5;
  const CouplingStepReport failed = scalar.run();
  EXPECT_FALSE(failed.converged);
  EXPECT_EQ(failed.restarts, 0);
  EXPECT_NE(failed.reason.find("structure solve failed at coupling iteration 4: load out of reach"), std::string::npos)
      << failed.reason;
  EXPECT_FALSE(is_interface_failure(failed.reason)) << failed.reason;  // a solver's failure, not the iteration's
  scalar.options.max_restarts = 1;
  const CouplingStepReport restarted = scalar.run();
  ASSERT_TRUE(restarted.converged) << restarted.reason;
  EXPECT_EQ(restarted.restarts, 1);
  EXPECT_NEAR(scalar.converged_load, 1.0 / 3.0, 1e-9);
}

// A coupled step may solve the chip several times with different interface loads; the last trial is
// what the step accepts, exactly as if that load had been the only one (dynamic, three steps).
TEST(CoupledStep, TheLastTrialIsTheAcceptedStep) {
  const spline::SplineCurve surface = periodic_curve(2, 16, kInterval, chip_height);
  const auto build = [&] {
    auto problem = std::make_unique<solid::SolidProblem>(
        solid::IgaSpace(solid::chip_patch(surface, {.degree = 2, .spans_x = 16, .spans_y = 3, .y_bottom = -2e-6})),
        std::make_shared<solid::LinearElastic>(205e9, 0.29, 7800.0));
    problem->fix_side(numerics::Side::bottom, 0);
    problem->fix_side(numerics::Side::bottom, 1);
    return problem;
  };
  const auto load = [&](const solid::SolidProblem& p, double scale) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(p.dof_count());
    for (int node : p.space().side_nodes(numerics::Side::top)) f.segment<2>(2 * node) = scale * Eigen::Vector2d(0.1, -1.0);
    return f;
  };
  solid::TimeIntegrationOptions o;
  o.dt = 1e-9;
  o.end_time = 3e-9;
  // Plain: the load 2 N/m per control point throughout.
  auto plain_problem = build();
  auto plain_load = std::make_shared<NodalLoad>(plain_problem->dof_count());
  plain_load->set(load(*plain_problem, 2.0));
  plain_problem->add_interaction(plain_load);
  solid::TimeIntegrator plain(*plain_problem, o);
  ASSERT_TRUE(plain.run().completed);
  // Coupled: each step first tries 1 N/m, then 2 N/m.
  auto coupled_problem = build();
  auto coupled_load = std::make_shared<NodalLoad>(coupled_problem->dof_count());
  coupled_problem->add_interaction(coupled_load);
  int trials = 0;
  o.coupled_step = [&](solid::TimeIntegrator& integrator, double t0, double dt, std::string& reason) {
    for (double scale : {1.0, 2.0}) {
      coupled_load->set(load(*coupled_problem, scale));
      if (!integrator.solve_trial(t0, dt, reason)) return false;
      ++trials;
    }
    return true;
  };
  coupled_load->set(load(*coupled_problem, 2.0));  // the same load at t = 0 as the plain run (the α-average uses it)
  solid::TimeIntegrator coupled(*coupled_problem, o);
  const solid::IntegrationReport report = coupled.run();
  ASSERT_TRUE(report.completed) << report.reason;
  EXPECT_EQ(trials, 6);
  EXPECT_LT((coupled.u() - plain.u()).norm(), 1e-9 * plain.u().norm());
  EXPECT_LT((coupled.v() - plain.v()).norm(), 1e-9 * plain.v().norm());
}

}  // namespace
}  // namespace mufric::coupling
