#include "micro/solid/solid_problem.hpp"

#include <algorithm>
#include <chrono>

#include "common/error.hpp"

namespace mufric::solid {

SolidProblem::SolidProblem(IgaSpace space, std::shared_ptr<const Material> material, MaterialState initial_state)
    : space_(std::move(space)), material_(std::move(material)),
      states_(space_.quadrature().size(), initial_state),
      constrained_(static_cast<size_t>(space_.dof_count()), false) {
  build_pattern();
}

void TangentAccumulator::add(int row, int col, double value) {
  const int* begin = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col];
  const int* end = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(begin, end, row);
  if (at == end || *at != row) throw Error("tangent: entry (" + std::to_string(row) + ", " + std::to_string(col) + ") is not in the pattern");
  matrix_.valuePtr()[at - matrix_.innerIndexPtr()] += value;
}

void SolidProblem::add_interaction(std::shared_ptr<const BoundaryInteraction> interaction) {
  interactions_.push_back(std::move(interaction));
  mass_ = SparseMatrix();
  build_pattern();
}

void SolidProblem::build_pattern() {
  const auto& qps = space_.quadrature();
  element_first_point_.clear();
  element_dofs_.clear();
  element_slots_.clear();
  // Quadrature points are stored element by element.
  for (size_t k = 0; k < qps.size(); ++k) {
    if (k == 0 || qps[k].element != qps[k - 1].element) element_first_point_.push_back(static_cast<int>(k));
  }
  element_first_point_.push_back(static_cast<int>(qps.size()));
  std::vector<Eigen::Triplet<double>> triplets;
  const size_t elements = element_first_point_.size() - 1;
  element_dofs_.resize(elements);
  for (size_t e = 0; e < elements; ++e) {
    const auto& nodes = qps[static_cast<size_t>(element_first_point_[e])].nodes;
    auto& dofs = element_dofs_[e];
    for (const int n : nodes) dofs.insert(dofs.end(), {2 * n, 2 * n + 1});
    for (const int r : dofs) {
      for (const int c : dofs) triplets.emplace_back(r, c, 0.0);
    }
  }
  for (const auto& interaction : interactions_) {
    for (const auto& group : interaction->coupled_nodes()) {
      for (const int a : group) {
        for (const int b : group) {
          for (int i = 0; i < 2; ++i) {
            for (int k = 0; k < 2; ++k) triplets.emplace_back(2 * a + i, 2 * b + k, 0.0);
          }
        }
      }
    }
  }
  pattern_.resize(space_.dof_count(), space_.dof_count());
  pattern_.setFromTriplets(triplets.begin(), triplets.end());
  pattern_.makeCompressed();
  // Slot of each local (row, col) in the compressed value array: found once, used every assembly.
  element_slots_.resize(elements);
  for (size_t e = 0; e < elements; ++e) {
    const auto& dofs = element_dofs_[e];
    auto& slots = element_slots_[e];
    slots.resize(dofs.size() * dofs.size());
    for (size_t c = 0; c < dofs.size(); ++c) {
      const int col = dofs[c];
      const int* rows_begin = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col];
      const int* rows_end = pattern_.innerIndexPtr() + pattern_.outerIndexPtr()[col + 1];
      for (size_t r = 0; r < dofs.size(); ++r) {
        slots[r + dofs.size() * c] = static_cast<int>(std::lower_bound(rows_begin, rows_end, dofs[r]) -
                                                      pattern_.innerIndexPtr());
      }
    }
  }
}

void SolidProblem::add_dirichlet(DirichletCondition condition) {
  if (condition.node < 0 || condition.node >= space_.node_count() || condition.component < 0 ||
      condition.component > 1) {
    throw Error("Dirichlet condition on node " + std::to_string(condition.node) + " component " +
                std::to_string(condition.component) + ": no such dof");
  }
  const int dof = 2 * condition.node + condition.component;
  if (constrained_[static_cast<size_t>(dof)]) {
    // A later condition on the same dof replaces the earlier one.
    std::erase_if(dirichlet_, [&](const DirichletCondition& d) { return 2 * d.node + d.component == dof; });
  }
  constrained_[static_cast<size_t>(dof)] = true;
  dirichlet_.push_back(std::move(condition));
}

void SolidProblem::fix_side(Side side, int component, double value, TimeFunction scale) {
  for (const int node : space_.side_nodes(side)) add_dirichlet({node, component, value, scale});
}

void SolidProblem::add_load(SideLoad load) {
  load_points_.push_back(space_.boundary(load.side));  // throws for a side the patch does not have
  loads_.push_back(std::move(load));
}

void SolidProblem::constrain(SparseMatrix& matrix) const {
  for (int col = 0; col < matrix.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator it(matrix, col); it; ++it) {
      if (constrained_[static_cast<size_t>(it.row())] || constrained_[static_cast<size_t>(col)]) {
        it.valueRef() = it.row() == col ? 1.0 : 0.0;
      }
    }
  }
}

void SolidProblem::zero_constrained(Eigen::VectorXd& vector) const {
  for (Eigen::Index i = 0; i < vector.size(); ++i) {
    if (constrained_[static_cast<size_t>(i)]) vector(i) = 0.0;
  }
}

void SolidProblem::apply_dirichlet(double t, Eigen::VectorXd& u) const {
  for (const auto& d : dirichlet_) u(2 * d.node + d.component) = d.value * (d.scale ? d.scale(t) : 1.0);
}

SolidProblem::Assembly SolidProblem::assemble(const Eigen::VectorXd& u, double dt, bool with_tangent) const {
  Assembly out;
  out.internal = Eigen::VectorXd::Zero(dof_count());
  out.states.resize(states_.size());
  out.stresses.resize(states_.size());
  if (with_tangent) out.tangent = pattern_;
  const auto& qps = space_.quadrature();
  const auto elements = static_cast<long>(element_first_point_.size() - 1);
  // Elements are independent: their local vectors and matrices are computed in parallel and
  // scattered afterwards in element order (so the sums do not depend on the thread count).
  std::vector<Eigen::VectorXd> local_f(static_cast<size_t>(elements));
  std::vector<Eigen::MatrixXd> local_k(with_tangent ? static_cast<size_t>(elements) : 0);
  std::vector<std::string> failure(static_cast<size_t>(elements));
#pragma omp parallel for schedule(dynamic, 16)
  for (long e = 0; e < elements; ++e) {
    const auto ue = static_cast<size_t>(e);
    const auto n = static_cast<Eigen::Index>(element_dofs_[ue].size());
    Eigen::VectorXd& f = local_f[ue];
    f.setZero(n);
    if (with_tangent) local_k[ue].setZero(n, n);
    Eigen::Matrix<double, 4, Eigen::Dynamic> a_dh(4, n);
    for (int k = element_first_point_[ue]; k < element_first_point_[ue + 1]; ++k) {
      const QuadraturePoint& q = qps[static_cast<size_t>(k)];
      const StressResponse r = material_->update(IgaSpace::gradient(q, u), states_[static_cast<size_t>(k)], dt);
      if (!r.ok) {
        failure[ue] = r.reason + " at X = (" + std::to_string(q.position.x()) + ", " + std::to_string(q.position.y()) + ")";
        break;
      }
      out.states[static_cast<size_t>(k)] = r.state;
      out.stresses[static_cast<size_t>(k)] = r.stress;
      const Eigen::Index nen = q.gradients.cols();
      // f_int[a, i] += S_ij ∂R_a/∂X_j w (the element's nodes are the quadrature point's, in order)
      for (Eigen::Index a = 0; a < nen; ++a) f.segment<2>(2 * a).noalias() += q.weight * (r.stress * q.gradients.col(a));
      if (!with_tangent) continue;
      // K_e += w (∂H/∂u)ᵀ A (∂H/∂u), A = ∂P/∂H, where δH_kl = δu_k ∂R_b/∂X_l: column (2b + k) of
      // ∂H/∂u is ∇R_b in rows 2k, 2k+1 and zero elsewhere. Written out with that sparsity, as a
      // dense product it was half zeros and went through Eigen's GEMM packing (7 % of a run).
      const auto& g = q.gradients;
      for (Eigen::Index b = 0; b < nen; ++b) {
        for (int kk = 0; kk < 2; ++kk) {
          a_dh.col(2 * b + kk) = r.tangent.col(2 * kk) * g(0, b) + r.tangent.col(2 * kk + 1) * g(1, b);
        }
      }
      Eigen::MatrixXd& k_e = local_k[ue];
      for (Eigen::Index c = 0; c < n; ++c) {
        const Eigen::Vector4d column = q.weight * a_dh.col(c);
        for (Eigen::Index a = 0; a < nen; ++a) {
          k_e(2 * a, c) += g(0, a) * column(0) + g(1, a) * column(1);
          k_e(2 * a + 1, c) += g(0, a) * column(2) + g(1, a) * column(3);
        }
      }
    }
  }
  for (long e = 0; e < elements; ++e) {
    const auto ue = static_cast<size_t>(e);
    if (!failure[ue].empty()) {
      out.ok = false;
      out.reason = failure[ue];
      return out;
    }
    const auto& dofs = element_dofs_[ue];
    const auto n = static_cast<Eigen::Index>(dofs.size());
    for (Eigen::Index r = 0; r < n; ++r) out.internal(dofs[static_cast<size_t>(r)]) += local_f[ue](r);
    if (!with_tangent) continue;
    double* values = out.tangent.valuePtr();
    const auto& slots = element_slots_[ue];
    for (Eigen::Index c = 0; c < n; ++c) {
      for (Eigen::Index r = 0; r < n; ++r) values[slots[static_cast<size_t>(r + n * c)]] += local_k[ue](r, c);
    }
  }
  // Every element succeeded (a failure returned above): the boundary interactions come on top.
  const auto start = std::chrono::steady_clock::now();
  TangentAccumulator accumulator(out.tangent);
  for (const auto& interaction : interactions_) {
    if (!interaction->add(u, out.internal, with_tangent ? &accumulator : nullptr, out.reason)) {
      out.ok = false;
      break;
    }
  }
  out.seconds_interactions = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

Eigen::VectorXd SolidProblem::external(double t) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dof_count());
  for (size_t l = 0; l < loads_.size(); ++l) {
    const SideLoad& load = loads_[l];
    const double s = load.scale ? load.scale(t) : 1.0;
    for (const auto& bp : load_points_[l]) {
      const Eigen::Vector2d traction = s * (load.traction - load.pressure * bp.normal);
      for (size_t a = 0; a < bp.nodes.size(); ++a) {
        f.segment<2>(2 * bp.nodes[a]) += bp.values(static_cast<Eigen::Index>(a)) * bp.weight * traction;
      }
    }
  }
  return f;
}

const SparseMatrix& SolidProblem::mass() const {
  if (mass_.nonZeros() > 0) return mass_;
  mass_ = pattern_;
  double* values = mass_.valuePtr();
  const auto& qps = space_.quadrature();
  const double rho = material_->density();
  for (size_t e = 0; e + 1 < element_first_point_.size(); ++e) {
    const auto& slots = element_slots_[e];
    const auto n = static_cast<Eigen::Index>(element_dofs_[e].size());
    for (int k = element_first_point_[e]; k < element_first_point_[e + 1]; ++k) {
      const QuadraturePoint& q = qps[static_cast<size_t>(k)];
      const Eigen::Index nen = q.values.size();
      for (Eigen::Index b = 0; b < nen; ++b) {
        for (Eigen::Index a = 0; a < nen; ++a) {
          const double m = rho * q.values(a) * q.values(b) * q.weight;
          for (int i = 0; i < 2; ++i) values[slots[static_cast<size_t>((2 * a + i) + n * (2 * b + i))]] += m;
        }
      }
    }
  }
  return mass_;
}

double SolidProblem::elastic_energy(const Eigen::VectorXd& u) const {
  return 0.5 * u.dot(assemble(u, 1.0, false).internal);
}

}  // namespace mufric::solid
