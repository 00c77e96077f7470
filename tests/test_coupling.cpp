// Partitioned coupling on the case that decides the scheme: an enclosed pocket of incompressible
// lubricant under a rigid piston loaded by a pressure (the incompressibility dilemma of Küttler,
// Förster & Wall, Comput. Mech. 38, 2006). The exact answer: the piston cannot move, the pocket keeps
// its volume and its pressure equals the applied one.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "micro/coupling/partitioned.hpp"
#include "micro/fluid/mesh_update.hpp"
#include "micro/fluid/navier_stokes.hpp"

namespace mufric::coupling {
namespace {

using fluid::Side;

enum class Scheme { dirichlet_neumann, robin_neumann };

// A 2 µm × 1 µm pocket of seed 000's lubricant; the piston is its top side, a 1 µm steel plate
// (7800 kg/m³) pushed down by `applied` Pa, integrated by backward Euler like the fluid.
struct PistonPocket {
  static constexpr double kWidth = 2e-6, kHeight = 1e-6, kPlateMassPerArea = 7800.0 * 1e-6;  // kg/m²
  double applied = 1e6;   // Pa
  double dt = 1e-9;       // s
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
  explicit PistonPocket(Scheme s)
      : scheme(s),
        ns(fluid::FluidSpace(fluid::rectangle_patch(2, 8, 4, Eigen::Vector2d::Zero(), Eigen::Vector2d(kWidth, kHeight), false)),
           options(s)) {
    mesh_start = ns.space().displacement();
  }

  // α_R: the plate's inertia per area and step, m/(B Δt), makes the Robin–Neumann iteration of this
  // linear problem nilpotent (the fluid's Robin traction then carries exactly the plate's response);
  // `robin_factor` detunes it.
  double robin_factor = 1.0;
  double robin_weight() const { return robin_factor * kPlateMassPerArea / dt; }

  // Fluid: the piston at δ (interface displacement, 1 value) → the traction σn on the fluid's top
  // side at its Gauss points (x, y per point).
  bool fluid(const Eigen::VectorXd& delta, const Eigen::VectorXd& previous, Eigen::VectorXd& load, std::string& reason) {
    ns.space().set_displacement(mesh_start);
    std::vector<std::pair<int, Eigen::Vector2d>> prescribed;
    for (Side side : {Side::bottom, Side::left, Side::right}) {
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
      const fluid::BoundaryField traction = [h, parameters](const Eigen::Vector2d&, double t) {
        const auto it = std::lower_bound(parameters.begin(), parameters.end(), t - 1e-15);
        const auto i = static_cast<Eigen::Index>(it - parameters.begin());
        return Eigen::Vector2d(h.segment<2>(2 * i));
      };
      conditions.push_back({Side::top, fluid::SideConditionKind::robin, piston, traction, robin_weight()});
    }
    for (Side side : {Side::left, Side::right, Side::bottom}) conditions.push_back({side, fluid::SideConditionKind::velocity, wall, {}, 0.0});
    ns.set_conditions(conditions);
    const fluid::FluidStepReport r = ns.solve_step(dt);
    if (!r.converged) {
      reason = r.reason;
      return false;
    }
    const auto samples = scheme == Scheme::robin_neumann ? ns.robin_traction(Side::top) : ns.side_traction(Side::top);
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
    const double mass = kPlateMassPerArea * kWidth;
    const double velocity = piston_velocity_start + dt * (fluid_force - applied * kWidth) / mass;
    delta = Eigen::VectorXd::Constant(1, piston_start + dt * velocity);
    return true;
  }
  static constexpr Side kTop = Side::top;

  struct Outcome {
    bool converged = true;
    std::string reason;
    int iterations = 0;
    double piston = 0.0, pressure = 0.0, area = 0.0;
  };

  Outcome run(int steps, const CouplingOptions& options) {
    InterfaceAccelerator accelerator(options);
    const PartitionedSolvers solvers{
        [this](const Eigen::VectorXd& load, Eigen::VectorXd& d, std::string& why) { return structure(load, d, why); },
        [this](const Eigen::VectorXd& d, const Eigen::VectorXd& load, Eigen::VectorXd& new_load, std::string& why) {
          return fluid(d, load, new_load, why);
        }};
    Outcome out;
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(1);
    Eigen::VectorXd load = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(ns.space().side_points(Side::top).size()));
    for (int n = 0; n < steps; ++n) {
      ns.begin_step();
      mesh_start = ns.space().displacement();
      const CouplingStepReport r = coupled_step(solvers, load, delta, accelerator, options);
      out.iterations += r.iterations;
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
    }
    out.piston = piston_start;
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
    if (r.converged) EXPECT_LT(q.iterations, r.iterations) << "alpha_R x " << factor;
  }
}

}  // namespace
}  // namespace mufric::coupling
