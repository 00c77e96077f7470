#include "micro/fluid/navier_stokes.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "common/error.hpp"

namespace mufric::fluid {

namespace {

// The velocity gradient ∇v (rows: component, columns: derivative), Laplacian and ∇(∇·v) at a point.
struct VelocityDerivatives {
  Eigen::Matrix2d gradient = Eigen::Matrix2d::Zero();
  Eigen::Vector2d laplacian = Eigen::Vector2d::Zero();
  Eigen::Vector2d grad_div = Eigen::Vector2d::Zero();
  Eigen::Vector2d pressure_gradient = Eigen::Vector2d::Zero();
};

Eigen::Matrix2d hessian(const PhysicalPoint& q, Eigen::Index a) {
  Eigen::Matrix2d h;
  h << q.hessians(0, a), q.hessians(1, a), q.hessians(1, a), q.hessians(2, a);
  return h;
}

double parameter_along(const ParametricPoint& p, Side side) {
  return (side == Side::bottom || side == Side::top) ? p.u : p.v;
}

// α at a point of a side: the Robin weight times its share there (0 on velocity and traction sides).
double robin_weight_at(const SideCondition& c, const Eigen::Vector2d& x, double t) {
  if (c.kind != SideConditionKind::robin) return 0.0;
  return c.robin_share ? c.robin_weight * c.robin_share(x, t) : c.robin_weight;
}

void check_properties(const FluidProperties& fluid) {
  if (!(fluid.density > 0.0) || !(fluid.viscosity > 0.0)) throw Error("fluid: density and viscosity must be positive");
  if (!(fluid.bulk_modulus >= 0.0) || !std::isfinite(fluid.bulk_modulus)) {
    throw Error("fluid: bulk_modulus must be finite and >= 0 (0: incompressible)");
  }
  if (!(fluid.pressure_stiffening >= 0.0) || !std::isfinite(fluid.pressure_stiffening)) {
    throw Error("fluid: pressure_stiffening must be finite and >= 0");
  }
}

}  // namespace

double out_of_plane_leak_coefficient(double film, double viscosity, double leak_length) {
  if (!(film >= 0.0) || !(viscosity > 0.0) || !(leak_length > 0.0)) {
    throw Error("fluid: a leak needs a film >= 0, a positive viscosity and a positive leak length");
  }
  return film * film / (6.0 * viscosity * leak_length * leak_length);
}

double log_density_ratio(const FluidProperties& fluid, double pressure) {
  if (!(fluid.bulk_modulus > 0.0)) return 0.0;
  if (pressure < 0.0) return pressure / fluid.bulk_modulus;
  return std::log1p(pressure / fluid.bulk_modulus / (1.0 + fluid.pressure_stiffening * pressure));
}

double log_density_ratio_derivative(const FluidProperties& fluid, double pressure) {
  if (!(fluid.bulk_modulus > 0.0)) return 0.0;
  if (pressure < 0.0) return 1.0 / fluid.bulk_modulus;
  const double stiffened = 1.0 + fluid.pressure_stiffening * pressure;
  const double excess = pressure / fluid.bulk_modulus / stiffened;  // ρ/ρ₀ − 1
  return 1.0 / (fluid.bulk_modulus * stiffened * stiffened) / (1.0 + excess);
}

NavierStokes::NavierStokes(FluidSpace space, NavierStokesOptions options)
    : space_(std::move(space)), options_(std::move(options)) {
  check_properties(options_.fluid);
  if (options_.pinned_pressure_node && (*options_.pinned_pressure_node < 0 || *options_.pinned_pressure_node >= space_.node_count())) {
    throw Error("fluid: pinned_pressure_node is not a control point of the patch");
  }
  state_ = Eigen::VectorXd::Zero(3 * space_.node_count());
  old_state_ = state_;
  mesh_velocity_ = Eigen::VectorXd::Zero(2 * space_.node_count());
}

void NavierStokes::set_properties(const FluidProperties& fluid) {
  check_properties(fluid);
  options_.fluid = fluid;
}

void NavierStokes::set_mesh(const Eigen::VectorXd& displacement, const Eigen::VectorXd& mesh_velocity) {
  if (mesh_velocity.size() != 2 * space_.node_count()) throw Error("fluid: mesh velocity has the wrong size");
  space_.set_displacement(displacement);
  mesh_velocity_ = mesh_velocity;
}

void NavierStokes::set_state(const Eigen::VectorXd& state) {
  if (state.size() != state_.size()) throw Error("fluid: state has the wrong size");
  state_ = state;
}

void NavierStokes::prescribed(std::vector<char>& fixed, Eigen::VectorXd& values) const {
  fixed.assign(static_cast<size_t>(state_.size()), 0);
  values = Eigen::VectorXd::Zero(state_.size());
  for (const auto& c : conditions_) {
    if (c.kind != SideConditionKind::velocity) continue;
    if (!c.velocity) throw Error("fluid: a velocity side needs its velocity");
    for (const auto& [node, value] : space_.interpolate_on_side(c.side, c.velocity)) {
      for (int k = 0; k < 2; ++k) {
        fixed[static_cast<size_t>(3 * node + k)] = 1;
        values(3 * node + k) = value(k);
      }
    }
  }
  if (options_.pinned_pressure_node) {
    fixed[static_cast<size_t>(3 * *options_.pinned_pressure_node + 2)] = 1;
    values(3 * *options_.pinned_pressure_node + 2) = options_.pinned_pressure;
  }
}

double NavierStokes::integrate_over_leak(const std::function<double(double, double)>& integrand) const {
  double sum = 0.0;
  for (int e = 0; e < space_.element_count(); ++e) {
    for (const ParametricPoint& p : space_.element_points(e)) {
      const PhysicalPoint q = space_.map(p);
      sum += q.weight * integrand(leak_.coefficient(q.position, p.u), pressure(p));
    }
  }
  return sum;
}

double NavierStokes::leak_target_pressure() const {
  if (!leak_.coefficient || leak_.target == LeakTarget::ambient) return leak_.ambient_pressure;
  const double total = integrate_over_leak([](double k, double) { return k; });
  return total > 0.0 ? integrate_over_leak([](double k, double p) { return k * p; }) / total : 0.0;
}

// Where local contributions go: the residual of every free row and the Jacobian's triplets (a
// prescribed row gets u − ū and a unit diagonal at the end).
struct NavierStokes::GlobalSystem {
  const std::vector<char>& fixed;
  Eigen::VectorXd& residual;
  std::vector<Eigen::Triplet<double>> triplets;
  void add(const std::vector<int>& nodes, const Eigen::VectorXd& r, const Eigen::MatrixXd& k) {
    const auto n = static_cast<Eigen::Index>(nodes.size());
    for (Eigen::Index a = 0; a < 3 * n; ++a) {
      const int row = 3 * nodes[static_cast<size_t>(a / 3)] + static_cast<int>(a % 3);
      if (fixed[static_cast<size_t>(row)]) continue;
      residual(row) += r(a);
      for (Eigen::Index b = 0; b < 3 * n; ++b) {
        if (k(a, b) != 0.0) triplets.emplace_back(row, 3 * nodes[static_cast<size_t>(b / 3)] + static_cast<int>(b % 3), k(a, b));
      }
    }
  }
};

struct NavierStokes::AssemblyConstants {
  double rho, mu, nu, inv_dt;
  // ∂(ln ρ)/∂t at the mesh's points (ALE), backward Euler; the convective part c·∇(ln ρ) is left
  // out: the liquid's speeds are ~1e-7 of its sound speed, so it is that much smaller than ∇·v.
  bool compressible;
  Eigen::Vector2d body;
  bool mean_leak;       // LeakTarget::mean: the sink toward p̄, added once p̄ is known
  double leak_ambient;  // the pressure the sink drains toward in the element loop (0 for the mean leak)
};

struct NavierStokes::LocalSystem {
  Eigen::VectorXd r;
  Eigen::MatrixXd k;
  Eigen::VectorXd advect;                // c·∇N_b at a point
  std::vector<Eigen::Matrix2d> dstrong;  // ∂(strong)/∂v_b at a point
  void reset(Eigen::Index n) {
    advect.resize(n);
    dstrong.resize(static_cast<size_t>(n));
    r = Eigen::VectorXd::Zero(3 * n);
    k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  }
};

// The mean-pressure leak's sink is κ(p − p̄) with p̄ = ∫κp/∫κ: assembled as κp, then −(∂R/∂p̄) p̄
// added once p̄ is known (∂R/∂p̄ collects −κ N_a in continuity and LSIC's share in momentum).
struct NavierStokes::MeanLeakSums {
  Eigen::VectorXd per_mean, mean_weights;  // −∂R/∂p̄, and ∫κ N_b at each pressure dof (mean leak only)
  double total = 0.0;                      // ∫κ
};

void NavierStokes::add_point(const ParametricPoint& p, const std::vector<int>& nodes, const AssemblyConstants& constants,
                             const std::vector<char>& fixed, LocalSystem& local, MeanLeakSums& leak_sums) const {
  const double rho = constants.rho, mu = constants.mu, nu = constants.nu, inv_dt = constants.inv_dt;
  const Eigen::Vector2d& body = constants.body;
  const auto n = static_cast<Eigen::Index>(nodes.size());
  Eigen::VectorXd& r = local.r;
  Eigen::MatrixXd& k = local.k;
  Eigen::VectorXd& advect = local.advect;
  std::vector<Eigen::Matrix2d>& dstrong = local.dstrong;
  const PhysicalPoint q = space_.map(p);
  const double wt = q.weight;
  const Eigen::Vector2d v = velocity(p), v_old = FluidSpace::interpolate2(p, old_state_, 3, 0);
  const Eigen::Vector2d w = FluidSpace::interpolate2(p, mesh_velocity_, 2, 0);
  const double pressure_here = pressure(p);
  double density_rate = 0.0, density_rate_per_pressure = 0.0;  // ∂(ln ρ)/∂t and its derivative in p
  if (constants.compressible) {
    const double old_pressure = FluidSpace::interpolate1(p, old_state_, 3, 2);
    density_rate = inv_dt * (log_density_ratio(options_.fluid, pressure_here) - log_density_ratio(options_.fluid, old_pressure));
    density_rate_per_pressure = inv_dt * log_density_ratio_derivative(options_.fluid, pressure_here);
  }
  const double leak = leak_.coefficient ? leak_.coefficient(q.position, p.u) : 0.0;  // κ here
  const double sink = leak * (pressure_here - constants.leak_ambient);
  leak_sums.total += wt * leak;
  VelocityDerivatives d;
  for (Eigen::Index a = 0; a < n; ++a) {
    const Eigen::Vector2d va = state_.segment<2>(3 * nodes[static_cast<size_t>(a)]);
    const double pa = state_(3 * nodes[static_cast<size_t>(a)] + 2);
    const Eigen::Matrix2d h = hessian(q, a);
    d.gradient += va * q.gradients.col(a).transpose();
    d.laplacian += (h(0, 0) + h(1, 1)) * va;
    d.grad_div += h * va;
    d.pressure_gradient += pa * q.gradients.col(a);
  }
  const Eigen::Vector2d c = v - w;  // convective velocity relative to the mesh
  const double divergence = d.gradient.trace();
  // Continuity's residual, whose least-squares (LSIC) term must vanish on an exact solution.
  const double continuity = divergence + density_rate + sink;
  const double continuity_per_pressure = density_rate_per_pressure + leak;
  // τ_M = (4/Δt² + c·G c + C_I ν² G:G)^(−1/2), ν_C = 1/(τ_M tr G) (Bazilevs et al. 2007, eq. 63–65).
  const double tau_m = 1.0 / std::sqrt(4.0 * inv_dt * inv_dt + c.dot(q.metric * c) +
                                       kInverseEstimateConstant * nu * nu * q.metric.squaredNorm());
  const double nu_c = 1.0 / (tau_m * q.metric.trace());
  const Eigen::Vector2d inertia = rho * ((v - v_old) * inv_dt + d.gradient * c);
  const Eigen::Vector2d strong = inertia + d.pressure_gradient - mu * (d.laplacian + d.grad_div) - rho * body;
  const Eigen::Matrix2d sym = d.gradient + d.gradient.transpose();
  // Per shape function b, once per point (not once per a): c·∇N_b, ΔN_b and ∂(strong_i)/∂v_bk =
  // ρ(δ_ik(N_b/Δt + c·∇N_b) + N_b ∂_k v_i) − μ(δ_ik ΔN_b + ∂_i∂_k N_b).
  for (Eigen::Index b = 0; b < n; ++b) {
    advect(b) = c.dot(q.gradients.col(b));
    const Eigen::Matrix2d hb = hessian(q, b);
    Eigen::Matrix2d& ds = dstrong[static_cast<size_t>(b)];
    ds = rho * q.values(b) * d.gradient - mu * hb;
    ds.diagonal().array() += rho * (q.values(b) * inv_dt + advect(b)) - mu * (hb(0, 0) + hb(1, 1));
  }

  for (Eigen::Index a = 0; a < n; ++a) {
    const double na = q.values(a);
    const Eigen::Vector2d ga = q.gradients.col(a);
    for (int i = 0; i < 2; ++i) {
      r(3 * a + i) += wt * (na * (inertia(i) - rho * body(i)) + mu * sym.row(i).dot(ga) - pressure_here * ga(i) +
                            tau_m * advect(a) * strong(i) + rho * nu_c * ga(i) * continuity);
    }
    r(3 * a + 2) += wt * (na * continuity + tau_m / rho * ga.dot(strong));
    for (Eigen::Index b = 0; b < n; ++b) {
      const double nb = q.values(b);
      const Eigen::Vector2d gb = q.gradients.col(b);
      const Eigen::Matrix2d& ds = dstrong[static_cast<size_t>(b)];
      const double mass_advection = na * rho * (nb * inv_dt + advect(b)), diffusion = mu * ga.dot(gb);
      for (int i = 0; i < 2; ++i) {
        for (int kk = 0; kk < 2; ++kk) {
          const double galerkin = (i == kk ? mass_advection + diffusion : 0.0) + na * rho * nb * d.gradient(i, kk) +
                                  mu * ga(kk) * gb(i);
          const double supg = tau_m * (advect(a) * ds(i, kk) + nb * ga(kk) * strong(i));
          k(3 * a + i, 3 * b + kk) += wt * (galerkin + supg + rho * nu_c * ga(i) * gb(kk));
        }
        k(3 * a + i, 3 * b + 2) +=
            wt * (-nb * ga(i) + tau_m * advect(a) * gb(i) + rho * nu_c * ga(i) * continuity_per_pressure * nb);
      }
      for (int kk = 0; kk < 2; ++kk) {
        k(3 * a + 2, 3 * b + kk) += wt * (na * gb(kk) + tau_m / rho * ga.dot(ds.col(kk)));
      }
      k(3 * a + 2, 3 * b + 2) += wt * (tau_m / rho * ga.dot(gb) + na * continuity_per_pressure * nb);
    }
    if (constants.mean_leak) {
      const auto row = static_cast<Eigen::Index>(3 * nodes[static_cast<size_t>(a)]);
      if (!fixed[static_cast<size_t>(row + 2)]) leak_sums.per_mean(row + 2) += wt * na * leak;
      for (int i = 0; i < 2; ++i) {
        if (!fixed[static_cast<size_t>(row + i)]) leak_sums.per_mean(row + i) += wt * rho * nu_c * ga(i) * leak;
      }
      leak_sums.mean_weights(row + 2) += wt * na * leak;
    }
  }
}

// Traction and Robin sides: −∫ N_a h and, for Robin, −∫ N_a α (g − v) (eq. 13 in weak form).
void NavierStokes::add_side_conditions(GlobalSystem& system) const {
  for (const auto& c : conditions_) {
    if (c.kind == SideConditionKind::velocity) continue;
    if (c.kind == SideConditionKind::robin && !c.velocity) throw Error("fluid: a Robin side needs its velocity");
    for (const ParametricPoint& p : space_.side_points(c.side)) {
      const PhysicalPoint q = space_.map(p, &c.side);
      const double t = parameter_along(p, c.side);
      const Eigen::Vector2d h = c.traction ? c.traction(q.position, t) : Eigen::Vector2d::Zero();
      const double alpha = robin_weight_at(c, q.position, t);
      Eigen::Vector2d load = h;
      if (alpha != 0.0) load += alpha * (c.velocity(q.position, t) - velocity(p));
      const auto n = static_cast<Eigen::Index>(p.nodes.size());
      Eigen::VectorXd r = Eigen::VectorXd::Zero(3 * n);
      Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
      for (Eigen::Index a = 0; a < n; ++a) {
        for (int i = 0; i < 2; ++i) {
          r(3 * a + i) -= q.weight * q.values(a) * load(i);
          for (Eigen::Index b = 0; b < n; ++b) k(3 * a + i, 3 * b + i) += q.weight * alpha * q.values(a) * q.values(b);
        }
      }
      system.add(p.nodes, r, k);
    }
  }
}

// The form owns the loops (elements, then sides), the point kernel the physics (MFEM's split of a
// form and its integrators; PetIGA's residual and Jacobian at a point).
void NavierStokes::assemble(double dt, const std::vector<char>& fixed, const Eigen::VectorXd& values,
                            Eigen::VectorXd& residual, Eigen::SparseMatrix<double>& jacobian, Eigen::VectorXd* rank_one_a,
                            Eigen::VectorXd* rank_one_b) const {
  const double inv_dt = dt > 0.0 ? 1.0 / dt : 0.0;
  const bool mean_leak = leak_.coefficient && leak_.target == LeakTarget::mean;
  const AssemblyConstants constants{.rho = options_.fluid.density,
                                    .mu = options_.fluid.viscosity,
                                    .nu = options_.fluid.viscosity / options_.fluid.density,
                                    .inv_dt = inv_dt,
                                    .compressible = options_.fluid.bulk_modulus > 0.0 && inv_dt > 0.0,
                                    .body = options_.body_force,
                                    .mean_leak = mean_leak,
                                    .leak_ambient = mean_leak ? 0.0 : leak_.ambient_pressure};
  residual = Eigen::VectorXd::Zero(state_.size());
  MeanLeakSums leak_sums;
  if (mean_leak) {
    leak_sums.per_mean = Eigen::VectorXd::Zero(state_.size());
    leak_sums.mean_weights = Eigen::VectorXd::Zero(state_.size());
  }
  GlobalSystem system{fixed, residual, {}};
  LocalSystem local;
  for (int e = 0; e < space_.element_count(); ++e) {
    const std::vector<int>& nodes = space_.element_nodes(e);
    local.reset(static_cast<Eigen::Index>(nodes.size()));
    for (const ParametricPoint& p : space_.element_points(e)) add_point(p, nodes, constants, fixed, local, leak_sums);
    system.add(nodes, local.r, local.k);
  }
  add_side_conditions(system);

  if (mean_leak && leak_sums.total > 0.0) {
    const Eigen::VectorXd b = leak_sums.mean_weights / leak_sums.total;  // ∂p̄/∂p
    residual -= leak_sums.per_mean * b.dot(state_);
    if (rank_one_a != nullptr) *rank_one_a = leak_sums.per_mean;
    if (rank_one_b != nullptr) *rank_one_b = b;
  } else {
    if (rank_one_a != nullptr) rank_one_a->resize(0);
    if (rank_one_b != nullptr) rank_one_b->resize(0);
  }
  for (Eigen::Index row = 0; row < state_.size(); ++row) {
    if (!fixed[static_cast<size_t>(row)]) continue;
    residual(row) = state_(row) - values(row);
    system.triplets.emplace_back(static_cast<int>(row), static_cast<int>(row), 1.0);
  }
  jacobian.resize(state_.size(), state_.size());
  jacobian.setFromTriplets(system.triplets.begin(), system.triplets.end());
}

FluidStepReport NavierStokes::solve_step(double dt) {
  if (dt < 0.0) throw Error("fluid: the time step must not be negative");
  FluidStepReport report;
  report.min_relative_jacobian = space_.min_relative_jacobian();
  if (!(report.min_relative_jacobian > 0.0)) {
    report.reason = "the fluid mesh has folded (min relative det J = " + std::to_string(report.min_relative_jacobian) + ")";
    return report;
  }
  const Eigen::VectorXd start = state_;
  std::vector<char> fixed;
  Eigen::VectorXd values;
  prescribed(fixed, values);
  for (Eigen::Index i = 0; i < state_.size(); ++i) {
    if (fixed[static_cast<size_t>(i)]) state_(i) = values(i);
  }
  if (const std::string why = enclosed_flux_violation(); !why.empty()) {
    report.reason = why;
    state_ = start;
    return report;
  }
  Eigen::VectorXd residual;
  Eigen::SparseMatrix<double> jacobian;
  double first = 0.0;
  Eigen::VectorXd rank_one_a, rank_one_b;  // the Jacobian's −a bᵀ (a mean-pressure leak)
  for (int it = 0; it <= options_.max_newton_iterations; ++it) {
    assemble(dt, fixed, values, residual, jacobian, &rank_one_a, &rank_one_b);
    const double norm = residual.norm();
    report.residual_history.push_back(norm);
    if (!std::isfinite(norm)) {
      report.reason = "the fluid residual is not finite at Newton iterate " + std::to_string(it);
      break;
    }
    if (it == 0) first = norm;
    // Row by row against the size of the terms that make it up (|J||x|): a residual at round-off
    // of its own terms is converged even when the first iterate was already (a uniform flow).
    const Eigen::VectorXd term_size = jacobian.cwiseAbs() * state_.cwiseAbs();
    const bool at_round_off = (residual.cwiseAbs().array() <= kNewtonResidualTolerance * term_size.array()).all();
    if (norm == 0.0 || at_round_off || (it > 0 && norm <= kNewtonResidualTolerance * first)) {
      report.converged = true;
      break;
    }
    if (it == options_.max_newton_iterations) {
      report.reason = "Newton did not converge in " + std::to_string(it) + " iterations (residual " +
                      std::to_string(norm / first) + " of the first)";
      break;
    }
    if (!solver_.factorize(jacobian)) {
      report.reason = "the fluid tangent could not be factorised: " + solver_.reason();
      break;
    }
    Eigen::VectorXd delta = solver_.solve(-residual);
    if (rank_one_a.size() > 0) {
      // (J − a bᵀ)⁻¹ by Sherman & Morrison (Ann. Math. Stat. 21, 1950): δ = y + z (bᵀy)/(1 − bᵀz), z = J⁻¹a.
      const Eigen::VectorXd z = solver_.solve(rank_one_a);
      const double denominator = 1.0 - rank_one_b.dot(z);
      if (!(std::abs(denominator) > 0.0)) {
        report.reason = "the fluid tangent with the mean-pressure leak is singular";
        break;
      }
      delta += z * (rank_one_b.dot(delta) / denominator);
    }
    if (!delta.allFinite()) {
      report.reason = "the fluid Newton correction is not finite";
      break;
    }
    state_ += delta;
    report.newton_iterations = it + 1;
    if (delta.norm() <= kNewtonStepTolerance * std::max(state_.norm(), std::numeric_limits<double>::min())) {
      report.converged = true;
      assemble(dt, fixed, values, residual, jacobian);
      report.residual_history.push_back(residual.norm());
      break;
    }
  }
  if (!report.converged) state_ = start;
  return report;
}

std::string NavierStokes::enclosed_flux_violation() const {
  if (options_.fluid.bulk_modulus > 0.0) return {};  // a compressible liquid takes any flux
  if (leak_.coefficient && leak_.target == LeakTarget::ambient) return {};  // so does one leaking out
  std::vector<char> given(4, 0);
  for (const auto& c : conditions_) {
    if (c.kind != SideConditionKind::velocity) return {};  // a traction or Robin side lets the volume change
    given[static_cast<size_t>(c.side)] = 1;
  }
  double flux = 0.0, size = 0.0;
  for (Side side : {Side::bottom, Side::top, Side::left, Side::right}) {
    if (!space_.has_side(side)) continue;
    if (!given[static_cast<size_t>(side)]) return {};  // a side without a condition is traction-free
    for (const ParametricPoint& p : space_.side_points(side)) {
      const PhysicalPoint q = space_.map(p, &side);
      const Eigen::Vector2d g = velocity(p);  // the boundary values are the prescribed ones here
      flux += q.weight * g.dot(q.normal);
      size += q.weight * g.norm();
    }
  }
  if (std::abs(flux) <= kEnclosedFluxTolerance * size) return {};
  std::ostringstream why;
  why << "the velocity given on the whole boundary changes the enclosed volume at " << flux
      << " m^2/s per unit depth: no incompressible flow satisfies it (an enclosed fluid needs a traction or Robin side)";
  return why.str();
}

double NavierStokes::leak_rate() const {
  if (!leak_.coefficient) return 0.0;
  const double target = leak_target_pressure();
  return integrate_over_leak([target](double k, double p) { return k * (p - target); });
}

double NavierStokes::leak_exchange_rate() const {
  if (!leak_.coefficient) return 0.0;
  const double target = leak_target_pressure();
  return 0.5 * integrate_over_leak([target](double k, double p) { return k * std::abs(p - target); });
}

std::vector<NavierStokes::TractionSample> NavierStokes::side_traction(Side side) const {
  std::vector<TractionSample> out;
  const double mu = options_.fluid.viscosity;
  for (const ParametricPoint& p : space_.side_points(side)) {
    const PhysicalPoint q = space_.map(p, &side);
    Eigen::Matrix2d gradient = Eigen::Matrix2d::Zero();
    for (size_t a = 0; a < p.nodes.size(); ++a) {
      gradient += state_.segment<2>(3 * p.nodes[a]) * q.gradients.col(static_cast<Eigen::Index>(a)).transpose();
    }
    const Eigen::Matrix2d sigma = -pressure(p) * Eigen::Matrix2d::Identity() + mu * (gradient + gradient.transpose());
    out.push_back({q.position, sigma * q.normal, q.normal, parameter_along(p, side), q.weight, velocity(p)});
  }
  return out;
}

std::vector<NavierStokes::TractionSample> NavierStokes::robin_traction(Side side) const {
  const SideCondition* robin = nullptr;
  for (const auto& c : conditions_) {
    if (c.side == side && c.kind == SideConditionKind::robin) robin = &c;
  }
  if (robin == nullptr) throw Error("fluid: robin_traction asked of a side without a Robin condition");
  std::vector<TractionSample> out;
  for (const ParametricPoint& p : space_.side_points(side)) {
    const PhysicalPoint q = space_.map(p, &side);
    const double t = parameter_along(p, side);
    Eigen::Vector2d traction = robin->traction ? robin->traction(q.position, t) : Eigen::Vector2d::Zero();
    const double alpha = robin_weight_at(*robin, q.position, t);
    const Eigen::Vector2d v = velocity(p);
    traction += alpha * (robin->velocity(q.position, t) - v);
    out.push_back({q.position, traction, q.normal, t, q.weight, v});
  }
  return out;
}

}  // namespace mufric::fluid
