#include "micro/solid/heat_conduction.hpp"

#include <algorithm>

#include "common/error.hpp"

namespace mufric::solid {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Element blocks summed over their points, then scattered: quadrature points are stored element by
// element, so one dense block per element keeps the triplet list ~(points per element) times shorter.
template <class PointMatrix>
Eigen::SparseMatrix<double> assemble_scalar(const IgaSpace& space, PointMatrix&& point_matrix) {
  const auto& qps = space.quadrature();
  Triplets triplets;
  Eigen::MatrixXd block;
  for (size_t k = 0; k < qps.size();) {
    const int element = qps[k].element;
    const auto& nodes = qps[k].nodes;
    const auto n = static_cast<Eigen::Index>(nodes.size());
    block.setZero(n, n);
    for (; k < qps.size() && qps[k].element == element; ++k) block += point_matrix(qps[k]);
    for (Eigen::Index a = 0; a < n; ++a) {
      for (Eigen::Index b = 0; b < n; ++b) triplets.emplace_back(nodes[static_cast<size_t>(a)], nodes[static_cast<size_t>(b)], block(a, b));
    }
  }
  Eigen::SparseMatrix<double> m(space.node_count(), space.node_count());
  m.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

}  // namespace

HeatConduction::HeatConduction(const IgaSpace& space, HeatConductionOptions options)
    : space_(space), options_(options),
      temperature_(Eigen::VectorXd::Constant(space.node_count(), options.held_temperature)),
      held_(static_cast<size_t>(space.node_count()), 0) {
  if (!(options_.conductivity >= 0.0) || !(options_.density > 0.0) || !(options_.specific_heat > 0.0)) {
    throw Error("heat conduction: conductivity must be >= 0, density and specific heat > 0");
  }
  const double rho_c = options_.density * options_.specific_heat;
  capacity_ = assemble_scalar(space_, [&](const QuadraturePoint& q) -> Eigen::MatrixXd {
    return (q.weight * rho_c) * q.values * q.values.transpose();
  });
  for (int node : space_.side_nodes(options_.held_side)) held_[static_cast<size_t>(node)] = 1;
}

Eigen::VectorXd HeatConduction::at_quadrature_points() const {
  const auto& qps = space_.quadrature();
  Eigen::VectorXd t(static_cast<Eigen::Index>(qps.size()));
  for (size_t k = 0; k < qps.size(); ++k) {
    double value = 0.0;
    for (size_t a = 0; a < qps[k].nodes.size(); ++a) value += qps[k].values(static_cast<Eigen::Index>(a)) * temperature_(qps[k].nodes[a]);
    t(static_cast<Eigen::Index>(k)) = value;
  }
  return t;
}

double HeatConduction::heat_content() const {
  return Eigen::VectorXd::Ones(temperature_.size()).dot(capacity_ * temperature_);
}

bool HeatConduction::step(const Eigen::VectorXd& u, double dt, std::vector<MaterialState>& states, std::string& reason,
                          const Eigen::VectorXd& boundary_heat) {
  const auto& qps = space_.quadrature();
  if (states.size() != qps.size()) throw Error("heat conduction: one material state per quadrature point expected");
  const double rho_c = options_.density * options_.specific_heat, k = options_.conductivity;
  const Eigen::VectorXd before = at_quadrature_points();
  if (boundary_heat.size() != 0 && boundary_heat.size() != temperature_.size()) {
    throw Error("heat conduction: boundary heat has " + std::to_string(boundary_heat.size()) + " entries for " +
                std::to_string(temperature_.size()) + " nodes");
  }
  // Backward Euler, multiplied by dt: (C + dt K) T₁ = C T₀ + ∫ R ρ₀c Δθ_adiabatic dV₀ + ∫ R q dΓ dt.
  Eigen::VectorXd rhs = capacity_ * temperature_;
  if (boundary_heat.size() != 0) rhs += boundary_heat;
  for (size_t q = 0; q < qps.size(); ++q) {
    const double heat = qps[q].weight * rho_c * (states[q].temperature - before(static_cast<Eigen::Index>(q)));
    for (size_t a = 0; a < qps[q].nodes.size(); ++a) rhs(qps[q].nodes[a]) += heat * qps[q].values(static_cast<Eigen::Index>(a));
  }
  Eigen::SparseMatrix<double> system = assemble_scalar(space_, [&](const QuadraturePoint& q) -> Eigen::MatrixXd {
    const Eigen::Matrix2d f = Eigen::Matrix2d::Identity() + IgaSpace::gradient(q, u);
    const Eigen::Matrix2d f_inv = f.inverse();
    const Eigen::Matrix2d conduction = (k * f.determinant()) * f_inv * f_inv.transpose();  // J C⁻¹ k
    return (q.weight * dt) * q.gradients.transpose() * conduction * q.gradients;
  });
  system += capacity_;
  // The held side: T = held_temperature, eliminated symmetrically (its columns move to the right side).
  const double held = options_.held_temperature;
  for (int col = 0; col < system.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(system, col); it; ++it) {
      const bool row_held = held_[static_cast<size_t>(it.row())] != 0, col_held = held_[static_cast<size_t>(col)] != 0;
      if (col_held && !row_held) rhs(it.row()) -= it.value() * held;
      if (row_held || col_held) it.valueRef() = it.row() == col ? 1.0 : 0.0;
    }
  }
  for (size_t node = 0; node < held_.size(); ++node) {
    if (held_[node]) rhs(static_cast<Eigen::Index>(node)) = held;
  }
  if (!solver_.factorize(system)) {
    reason = "heat conduction: " + solver_.reason();
    return false;
  }
  temperature_ = solver_.solve(rhs);
  const Eigen::VectorXd after = at_quadrature_points();
  for (size_t q = 0; q < qps.size(); ++q) states[q].temperature = after(static_cast<Eigen::Index>(q));
  return true;
}

}  // namespace mufric::solid
