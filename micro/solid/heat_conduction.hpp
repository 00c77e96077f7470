#pragma once
// Transient heat conduction in the chip, staggered with the mechanics (the isothermal split of
// Simo & Miehe, CMAME 98, 1992, sec. 3): each accepted mechanical step heats its quadrature points
// adiabatically (the material's Δθ = β σy Δε̄p / ρc); that heat, ρc Δθ per unit reference volume, is
// the source of one backward-Euler step of ρ₀c Ṫ = −∇₀·Q on the same spline space as the
// displacement, with the conductivity pulled back to the reference configuration, Q = −J C⁻¹ k ∇₀T
// (the referential heat flux of Fourier's law, Holzapfel, Nonlinear Solid Mechanics 2000, ch. 7), and
// the quadrature points then take the temperature of the conducted field. Heat entering through the
// boundary in the step (the contact's frictional heat) joins the source as a nodal load. One side is held at a
// temperature (the chip's bulk beneath the micro-model); the others are insulated (the rigid tool
// takes no heat) or periodic.
#include <vector>

#include <Eigen/Sparse>

#include "micro/solid/iga_space.hpp"
#include "micro/numerics/linear_solver.hpp"
#include "micro/solid/materials.hpp"

namespace mufric::solid {

struct HeatConductionOptions {
  double conductivity = 50.0;      // W/(m K)
  double density = 7800.0;         // kg/m³ (reference)
  double specific_heat = 450.0;    // J/(kg K)
  numerics::Side held_side = numerics::Side::bottom;   // held at held_temperature
  double held_temperature = 293.15;  // K; also the initial temperature everywhere
};

class HeatConduction {
 public:
  HeatConduction(const IgaSpace& space, HeatConductionOptions options);

  // One step of length dt after a mechanical step: `states` hold the start-of-step temperature plus
  // their adiabatic increment on entry, and the conducted temperature on return. u: the nodal
  // displacements at the end of the step (for J C⁻¹). boundary_heat: heat that entered through the
  // boundary during the step, per node (J per unit depth, ∫ R_a q dΓ dt; the frictional heat of the
  // contact), or empty. Returns false with a reason when the conduction matrix cannot be factorised.
  bool step(const Eigen::VectorXd& u, double dt, std::vector<MaterialState>& states, std::string& reason,
            const Eigen::VectorXd& boundary_heat = {});

  const Eigen::VectorXd& nodal_temperature() const { return temperature_; }
  // The temperature field at every quadrature point.
  Eigen::VectorXd at_quadrature_points() const;
  // ∫ ρ₀ c T dV₀ per unit depth (J/m): the heat content, for the energy balance.
  double heat_content() const;

 private:
  const IgaSpace& space_;
  HeatConductionOptions options_;
  Eigen::VectorXd temperature_;            // per control point, K
  Eigen::SparseMatrix<double> capacity_;   // ∫ ρ₀ c R_a R_b dV₀ (full storage)
  std::vector<char> held_;                 // per node: on the held side
  numerics::LinearSolver solver_{numerics::LinearSolverKind::cholesky};
};

}  // namespace mufric::solid
