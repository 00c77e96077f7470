#pragma once
// Incompressible Navier–Stokes in ALE form (seed 000 eq. 7–13) on a moving spline patch:
//   ρ(∂v/∂t|_χ + (v − w)·∇v) − ∇·σ = ρ b,  ∇·v = 0,  σ = −p I + η(∇v + ∇vᵀ),
// optionally with a barotropic density (FluidProperties) or a leak out of the plane (PressureLeak)
// in continuity;
// w the mesh velocity. Equal-order velocity and pressure, stabilised by SUPG/PSPG with grad-div
// (LSIC) and the element metric tensor's τ (Tezduyar, Adv. Appl. Mech. 28, 1992; τ as Bazilevs et
// al., CMAME 197, 2007, eq. 63–65), full strong residual including the viscous term, so the scheme
// is consistent: an exact solution in the discrete space (Couette, Poiseuille) is reproduced exactly.
// Implicit (backward) Euler in time as the paper, or steady; Newton with the stabilisation
// parameters frozen at the current iterate; UMFPACK solves. Boundary conditions per side: velocity
// (Dirichlet), traction (Neumann; none given = traction-free) and Robin α v + σn = h + α g (eq. 13).
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Sparse>

#include "micro/fluid/fluid_space.hpp"
#include "micro/numerics/linear_solver.hpp"

namespace mufric::fluid {

struct FluidProperties {  // seed 000 Table 2
  double density = 800.0;     // kg/m³
  double viscosity = 0.032;   // Pa s (dynamic)
  // K₀, Pa: 0 is incompressible (seed 000). A finite K₀ makes the liquid barotropic, ρ(p)/ρ₀ =
  // 1 + (p/K₀)/(1 + b p), and continuity D(ln ρ)/Dt + ∇·v = 0: a sealed pocket squeezed by ΔV/V takes
  // a pressure of about K₀ ΔV/V instead of an unbounded one. b = 0 is a linear density; b = 1.7 GPa⁻¹
  // with K₀ = 1/0.6 GPa⁻¹ is Dowson & Higginson's (Elasto-hydrodynamic Lubrication, 1966) law for
  // mineral oils, whose density saturates at 1 + 1/(K₀ b) of ρ₀. Below p = 0 (a traction the
  // liquid does not hold for long) the density stays linear in p with the slope at 0.
  double bulk_modulus = 0.0;
  double pressure_stiffening = 0.0;  // b, 1/Pa
};
// Dowson & Higginson's (1966) law: K₀ = 1/(0.6 GPa⁻¹), b = 1.7 GPa⁻¹.
inline constexpr double kDowsonHigginsonBulkModulus = 1e9 / 0.6;  // Pa
inline constexpr double kDowsonHigginsonStiffening = 1.7e-9;      // 1/Pa
// ln(ρ(p)/ρ₀) of FluidProperties' density law and its derivative in p.
double log_density_ratio(const FluidProperties& fluid, double pressure);
double log_density_ratio_derivative(const FluidProperties& fluid, double pressure);

// Newton stops when the residual of the free equations falls below this fraction of the first
// iterate's, or every equation's residual below this fraction of the size of its own terms (or the
// correction below kNewtonStepTolerance of the solution's size).
inline constexpr double kNewtonResidualTolerance = 1e-10;
inline constexpr double kNewtonStepTolerance = 1e-12;
// The inverse-estimate constant C_I of τ_M's viscous part for quadratic splines (Bazilevs et al.
// 2007, after eq. 65: C_I from an element-wise inverse inequality; 36 for quadratics).
inline constexpr double kInverseEstimateConstant = 36.0;
// A fluid with velocity given on its whole boundary is incompressible only if that velocity keeps
// its volume: a net boundary flux above this fraction of ∫|g| dΓ (far above what interpolating
// smooth boundary data leaves) has no solution and is refused.
inline constexpr double kEnclosedFluxTolerance = 1e-3;

struct NavierStokesOptions {
  FluidProperties fluid;
  Eigen::Vector2d body_force = Eigen::Vector2d::Zero();  // b, m/s² (per unit mass)
  int max_newton_iterations = 25;
  // An enclosed fluid with velocity given on its whole boundary has its pressure fixed only up to a
  // constant: pin this control point's pressure (Pa). Empty: the boundary conditions fix it.
  std::optional<int> pinned_pressure_node;
  double pinned_pressure = 0.0;
};

enum class SideConditionKind { velocity, traction, robin };
// A boundary value at a current position x on the side and its curve parameter t.
using BoundaryField = std::function<Eigen::Vector2d(const Eigen::Vector2d& x, double t)>;
using BoundaryScalar = std::function<double(const Eigen::Vector2d& x, double t)>;

// A value in the fluid's domain at a current position x and the point's parameter u along the patch.
using DomainScalar = std::function<double(const Eigen::Vector2d& x, double u)>;

// Liquid leaving the plane of the flow: continuity becomes ∇·v + κ(x)(p − p_a) = 0, a sink of
// κ(p − p_a) per unit volume (1/s) toward a pressure p_a out of the plane; κ ≥ 0 in 1/(Pa s). A 2D
// slice of a film whose liquid escapes sideways by Poiseuille flow (the thin-film limit of Reynolds'
// equation, Reynolds, Phil. Trans. R. Soc. 177, 1886) has κ = h²/(6ηL²) (out_of_plane_leak_coefficient).
// p_a is either a fixed ambient pressure (the liquid drains to, or where p < p_a is drawn from, the
// outside), or the fluid's own κ-weighted mean pressure p̄ = ∫κp/∫κ: the slice's neighbours out of
// the plane are, on average, the cell itself (a mean-field closure), so liquid moves between its
// parts around the contact spots and the volume of the whole is kept (∫κ(p − p̄) = 0).
enum class LeakTarget { ambient, mean };
struct PressureLeak {
  DomainScalar coefficient;        // κ, 1/(Pa s); empty: no leak
  double ambient_pressure = 0.0;   // p_a, Pa, for LeakTarget::ambient
  LeakTarget target = LeakTarget::ambient;
};
// κ of a film h thick (m) of viscosity η (Pa s) whose pressure falls to ambient a distance L (m) either
// side of the slice, across it: the out-of-plane Reynolds flow with a uniform sink, whose pressure is
// parabolic in z, leaves h³p/(6ηL²) per unit area of film, h²p/(6ηL²) per unit volume.
double out_of_plane_leak_coefficient(double film, double viscosity, double leak_length);

struct SideCondition {
  Side side = Side::bottom;
  SideConditionKind kind = SideConditionKind::velocity;
  BoundaryField velocity;   // g: velocity and Robin
  BoundaryField traction;   // h: traction and Robin (empty: zero)
  double robin_weight = 0.0;  // α_R, Pa s/m
  // Robin: the share of α_R in force at each point (empty: 1 everywhere); 0 makes the point a
  // traction point, σn = h (e.g. where the lubricant has cavitated off the wall).
  BoundaryScalar robin_share = {};
};

struct FluidStepReport {
  bool converged = false;
  std::string reason;                   // why not, when not converged
  std::vector<double> residual_history; // |R| of the free equations per Newton iterate
  int newton_iterations = 0;
  double min_relative_jacobian = 1.0;   // of the mesh this step was solved on
};

class NavierStokes {
 public:
  NavierStokes(FluidSpace space, NavierStokesOptions options);

  FluidSpace& space() { return space_; }
  const FluidSpace& space() const { return space_; }
  const NavierStokesOptions& options() const { return options_; }
  // New fluid properties from the next step on (continuation in the Reynolds number).
  void set_properties(const FluidProperties& fluid);
  // Conditions are applied in order: where two velocity sides share a corner control point the
  // later one sets it.
  void set_conditions(std::vector<SideCondition> conditions) { conditions_ = std::move(conditions); }
  // The leak of the next solves (an empty coefficient: none).
  void set_leak(PressureLeak leak) { leak_ = std::move(leak); }
  // ∫ κ (p − p_a) dΩ of the current state, m²/s per unit depth: the liquid leaving the plane (0 without
  // a leak, and to round-off with LeakTarget::mean).
  double leak_rate() const;
  // ½ ∫ κ |p − p_a| dΩ: the liquid moving out of the plane in one direction, m²/s per unit depth.
  double leak_exchange_rate() const;
  // The leak's target pressure p_a at the current state (Pa): the ambient one, or p̄.
  double leak_target_pressure() const;
  // The mesh of the end of the next step: displacement from the reference net and mesh velocity,
  // 2 per control point (ALE; zero for a fixed mesh).
  void set_mesh(const Eigen::VectorXd& displacement, const Eigen::VectorXd& mesh_velocity);

  // One backward-Euler step of length dt (s) from the current state, or the steady state (dt = 0).
  FluidStepReport step(double dt) {
    begin_step();
    return solve_step(dt);
  }
  FluidStepReport solve_steady() { return step(0.0); }
  // The same in two parts, for a partitioned coupling that solves one step several times: the
  // current state becomes the start of the step, and each solve starts from the start of the step's
  // state... (a failed solve leaves the state where it was).
  void begin_step() { old_state_ = state_; }
  FluidStepReport solve_step(double dt);

  // Nodal unknowns, 3 per control point: v_x, v_y, p.
  const Eigen::VectorXd& state() const { return state_; }
  void set_state(const Eigen::VectorXd& state);
  Eigen::Vector2d velocity(const ParametricPoint& p) const { return FluidSpace::interpolate2(p, state_, 3, 0); }
  double pressure(const ParametricPoint& p) const { return FluidSpace::interpolate1(p, state_, 3, 2); }
  Eigen::Vector2d velocity_at(double u, double v) const { return velocity(space_.at(u, v)); }
  double pressure_at(double u, double v) const { return pressure(space_.at(u, v)); }

  // At each Gauss point of a side: position, curve parameter, line-element weight, the fluid's
  // outward normal n and the traction σn on the fluid there (the wall beyond the side is loaded
  // by −σn: a pressure p pushes it along n).
  struct TractionSample {
    Eigen::Vector2d position, traction, normal;
    double parameter = 0.0, weight = 0.0;
    Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // the fluid's, at the point
  };
  std::vector<TractionSample> side_traction(Side side) const;
  // On a Robin side, the traction its condition imposes weakly, σn = h + α(g − v): the interface
  // load a Robin–Neumann coupling passes on (consistent with the fluid's weak equations, unlike the
  // pointwise σn of side_traction). Throws Error when the side has no Robin condition.
  std::vector<TractionSample> robin_traction(Side side) const;

 private:
  FluidSpace space_;
  NavierStokesOptions options_;
  std::vector<SideCondition> conditions_;
  PressureLeak leak_;
  Eigen::VectorXd state_, old_state_, mesh_velocity_;
  numerics::LinearSolver solver_{numerics::LinearSolverKind::lu};

  // Empty, or why the velocity given on an enclosed fluid's whole boundary admits no solution (its
  // net flux does not vanish: the incompressibility dilemma of a Dirichlet–Neumann coupling).
  std::string enclosed_flux_violation() const;
  // ∫ integrand(κ, p) dΩ over the quadrature points (a leak is set).
  double integrate_over_leak(const std::function<double(double, double)>& integrand) const;
  // The prescribed dofs (velocity sides, pinned pressure) and their values.
  void prescribed(std::vector<char>& fixed, Eigen::VectorXd& values) const;
  // Residual and Jacobian of the discrete equations at state_; a prescribed row is u − ū with a unit
  // diagonal.
  // With LeakTarget::mean the Jacobian is the sparse part plus the rank-one −a bᵀ of p̄'s dependence on
  // every pressure: a = ∂R/∂p̄ (column), b = ∂p̄/∂p (row); both empty otherwise.
  void assemble(double dt, const std::vector<char>& fixed, const Eigen::VectorXd& values, Eigen::VectorXd& residual,
                Eigen::SparseMatrix<double>& jacobian, Eigen::VectorXd* rank_one_a = nullptr,
                Eigen::VectorXd* rank_one_b = nullptr) const;
  // The pieces of assemble (defined in the .cpp): the global system local contributions go into, the
  // constants of one assembly, an element's local system with the point kernel's scratch, and the
  // mean-pressure leak's sums.
  struct GlobalSystem;
  struct AssemblyConstants;
  struct LocalSystem;
  struct MeanLeakSums;
  // The VMS point kernel: one quadrature point's share of its element's residual and Jacobian.
  void add_point(const ParametricPoint& p, const std::vector<int>& nodes, const AssemblyConstants& constants,
                 const std::vector<char>& fixed, LocalSystem& local, MeanLeakSums& leak) const;
  // The traction and Robin sides.
  void add_side_conditions(GlobalSystem& system) const;
};

}  // namespace mufric::fluid
