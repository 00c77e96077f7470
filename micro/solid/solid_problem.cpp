#include "micro/solid/solid_problem.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <tuple>

#include "common/error.hpp"

namespace mufric::solid {
namespace {

// Per-quadrature-point scratch of an element: a fixed array when the node count is a compile-time
// constant (an element has at most as many points as nodes), else a vector.
template <class T, int N>
struct PointArray : std::array<T, static_cast<size_t>(N)> {
  explicit PointArray(size_t /*points*/) {}
};
template <class T>
struct PointArray<T, Eigen::Dynamic> : std::vector<T> {
  explicit PointArray(size_t points) : std::vector<T>(points) {}
};

// Σ_q bᵀ A_q b for b = ∂F/∂u_e (x dofs move F's first row, y dofs its second) and A_q a symmetric
// 4 × 4 material matrix already weighted, in 2 × 2 blocks of nen × nen: block (i, k) = Gᵀ C_ik with G
// the points' shape-function gradients stacked (rows 2q, 2q + 1: ∂R/∂X, ∂R/∂Y) and C_ik the rows of
// A_ik g. A's major symmetry makes block (y, x) = (x, y)ᵀ, so three blocks are computed, summed over
// all points at once at the end so that each row of a block accumulates in registers instead of being
// read and written back once per point. Rows are padded with zeros to a multiple of 4 (9 → 12): whole
// AVX2 vectors, which Eigen's fixed-size expressions use (at width 9 the compiler kept 27 scalar
// accumulators). The displacement element and the F-bar element (with its modified A) share it.
template <int Nen>
class MaterialTangentBlocks {
 public:
  using Block = Eigen::Matrix<double, Nen, Nen>;

  MaterialTangentBlocks(int nen, int points, bool with_tangent)
      : nen_(nen), padded_(kPadded == Eigen::Dynamic ? nen : kPadded), g_rows_(PaddedRows::Zero(2 * points, padded_)) {
    if (with_tangent) cxx_ = cxy_ = cyy_ = PaddedRows::Zero(2 * points, padded_);
  }
  // Point q's gradients (2 × nen, row-major) into G.
  void set_gradients(int q, const double* gradients) {
    std::copy_n(gradients, nen_, g_rows_.row(2 * q).data());
    std::copy_n(gradients + nen_, nen_, g_rows_.row(2 * q + 1).data());
  }
  const double* gradient_x(int q) const { return g_rows_.row(2 * q).data(); }
  const double* gradient_y(int q) const { return g_rows_.row(2 * q + 1).data(); }
  void add_point(int q, const Eigen::Matrix4d& weighted_tangent) {
    for (const auto& [c, row, col] : {std::tuple{&cxx_, 0, 0}, std::tuple{&cxy_, 0, 2}, std::tuple{&cyy_, 2, 2}}) {
      const Eigen::Matrix2d a_ik = weighted_tangent.block<2, 2>(row, col);
      c->row(2 * q) = a_ik(0, 0) * g_rows_.row(2 * q) + a_ik(0, 1) * g_rows_.row(2 * q + 1);
      c->row(2 * q + 1) = a_ik(1, 0) * g_rows_.row(2 * q) + a_ik(1, 1) * g_rows_.row(2 * q + 1);
    }
  }
  // Blocks (x, x), (x, y) and (y, y) of Σ bᵀ A b.
  void blocks(Block& kxx, Block& kxy, Block& kyy) const {
    kxx.resize(nen_, nen_);
    kxy.resize(nen_, nen_);
    kyy.resize(nen_, nen_);
    for (int a = 0; a < nen_; ++a) {
      PaddedRow xx = PaddedRow::Zero(padded_), xy = PaddedRow::Zero(padded_), yy = PaddedRow::Zero(padded_);
      for (int r = 0; r < g_rows_.rows(); ++r) {
        const double g = g_rows_(r, a);
        xx.noalias() += g * cxx_.row(r);
        xy.noalias() += g * cxy_.row(r);
        yy.noalias() += g * cyy_.row(r);
      }
      kxx.row(a) = xx.head(nen_);
      kxy.row(a) = xy.head(nen_);
      kyy.row(a) = yy.head(nen_);
    }
  }

 private:
  static constexpr int kMaxRows = Nen == Eigen::Dynamic ? Eigen::Dynamic : 2 * Nen;
  static constexpr int kPadded = Nen == Eigen::Dynamic ? Eigen::Dynamic : (Nen + 3) / 4 * 4;
  using PaddedRows = Eigen::Matrix<double, Eigen::Dynamic, kPadded, Eigen::RowMajor, kMaxRows, kPadded>;
  using PaddedRow = Eigen::Matrix<double, 1, kPadded>;
  int nen_, padded_;
  PaddedRows g_rows_, cxx_, cxy_, cyy_;
};

}  // namespace

SolidProblem::SolidProblem(IgaSpace space, std::shared_ptr<const Material> material, MaterialState initial_state,
                           VolumetricTreatment volumetric)
    : space_(std::move(space)), material_(std::move(material)), volumetric_(volumetric),
      states_(space_.quadrature().size(), initial_state),
      constrained_(static_cast<size_t>(space_.dof_count()), false) {
  if (volumetric_ == VolumetricTreatment::mean_dilatation && !material_->finite_strain()) {
    throw Error("solid problem: the mean-dilatation (F-bar) element needs a finite-strain material");
  }
  build_pattern();
}

namespace {
// A weight in [0.5, 1.5) for the unordered pair {row, col} (Fibonacci hashing, Knuth TAOCP vol. 3 §6.4).
double pair_weight(int row, int col) {
  const auto lo = static_cast<std::uint64_t>(std::min(row, col)), hi = static_cast<std::uint64_t>(std::max(row, col));
  const std::uint64_t hash = ((hi << 32) | lo) * 0x9E3779B97F4A7C15ULL;
  return 0.5 + static_cast<double>(hash >> 11) * 0x1.0p-53;
}
}  // namespace

void TangentAccumulator::add(int row, int col, double value) {
  if (storage_ == numerics::MatrixStorage::lower_symmetric && row != col) {
    const double weighted = pair_weight(row, col) * value;
    (row < col ? upper_ : lower_) += weighted;
    magnitude_ += std::abs(weighted);
    if (row < col) return;
  }
  const int* begin = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col];
  const int* end = matrix_.innerIndexPtr() + matrix_.outerIndexPtr()[col + 1];
  const int* at = std::lower_bound(begin, end, row);
  if (at == end || *at != row) throw Error("tangent: entry (" + std::to_string(row) + ", " + std::to_string(col) + ") is not in the pattern");
  matrix_.valuePtr()[at - matrix_.innerIndexPtr()] += value;
}

std::optional<std::string> TangentAccumulator::asymmetry() const {
  if (storage_ != numerics::MatrixStorage::lower_symmetric) return std::nullopt;
  if (std::abs(upper_ - lower_) <= kSymmetryTolerance * magnitude_) return std::nullopt;
  char text[200];
  std::snprintf(text, sizeof text, "weighted sums of its off-diagonal entries %.17g above and %.17g below the diagonal",
                upper_, lower_);
  return std::string(text);
}

void SolidProblem::commit_interactions(const Eigen::VectorXd& u) {
  for (const auto& interaction : interactions_) interaction->commit(u);
}

void SolidProblem::add_interaction(std::shared_ptr<BoundaryInteraction> interaction) {
  interactions_.push_back(std::move(interaction));
  mass_ = full_mass_ = SparseMatrix();
  build_pattern();
}

numerics::Symmetry SolidProblem::tangent_symmetry() const {
  const bool symmetric = std::all_of(interactions_.begin(), interactions_.end(),
                                     [](const auto& interaction) { return interaction->symmetric_tangent(); });
  return symmetric ? numerics::Symmetry::symmetric : numerics::Symmetry::unsymmetric;
}

numerics::MatrixStorage SolidProblem::tangent_storage() const {
  return tangent_symmetry() == numerics::Symmetry::symmetric ? numerics::MatrixStorage::lower_symmetric
                                                             : numerics::MatrixStorage::full;
}

void SolidProblem::build_pattern() {
  const auto& qps = space_.quadrature();
  element_first_point_.clear();
  element_dofs_.clear();
  element_slots_.clear();
  element_nodes_.clear();
  // Quadrature points are stored element by element.
  for (size_t k = 0; k < qps.size(); ++k) {
    if (k == 0 || qps[k].element != qps[k - 1].element) element_first_point_.push_back(static_cast<int>(k));
  }
  element_first_point_.push_back(static_cast<int>(qps.size()));
  element_nodes_count_ = qps.empty() ? 0 : static_cast<int>(qps.front().nodes.size());
  for (size_t e = 0; e + 1 < element_first_point_.size(); ++e) {
    // The element kernel keeps two rows per point in arrays sized for (p + 1)(q + 1) points.
    if (element_first_point_[e + 1] - element_first_point_[e] > element_nodes_count_) {
      throw Error("solid problem: an element has more quadrature points than basis functions");
    }
  }
  point_gradients_.resize(qps.size() * 2 * static_cast<size_t>(element_nodes_count_));
  point_weights_.resize(qps.size());
  for (size_t k = 0; k < qps.size(); ++k) {
    if (static_cast<int>(qps[k].nodes.size()) != element_nodes_count_) {
      throw Error("solid problem: quadrature points with different numbers of basis functions");
    }
    // Row-major: the x-derivatives of all functions, then the y-derivatives.
    const Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::RowMajor> rows = qps[k].gradients;
    std::copy_n(rows.data(), 2 * element_nodes_count_, point_gradients_.begin() + static_cast<long>(k * 2 * element_nodes_count_));
    point_weights_[k] = qps[k].weight;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  const size_t elements = element_first_point_.size() - 1;
  element_dofs_.resize(elements);
  for (size_t e = 0; e < elements; ++e) {
    const auto& nodes = qps[static_cast<size_t>(element_first_point_[e])].nodes;
    element_nodes_.insert(element_nodes_.end(), nodes.begin(), nodes.end());
    auto& dofs = element_dofs_[e];
    for (int i = 0; i < 2; ++i) {
      for (const int n : nodes) dofs.push_back(2 * n + i);
    }
    for (const int r : dofs) {
      for (const int c : dofs) {
        if (r >= c) triplets.emplace_back(r, c, 0.0);
      }
    }
  }
  for (const auto& interaction : interactions_) {
    for (const auto& group : interaction->coupled_nodes()) {
      for (const int a : group) {
        for (const int b : group) {
          for (int i = 0; i < 2; ++i) {
            for (int k = 0; k < 2; ++k) {
              if (2 * a + i >= 2 * b + k) triplets.emplace_back(2 * a + i, 2 * b + k, 0.0);
            }
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
        slots[r + dofs.size() * c] = dofs[r] < col ? -1
                                                   : static_cast<int>(std::lower_bound(rows_begin, rows_end, dofs[r]) -
                                                                      pattern_.innerIndexPtr());
      }
    }
  }
  // Greedy colouring in element order (each element takes the first colour none of its neighbours
  // through a shared node has): elements of a colour touch disjoint dofs, so they add into the
  // global arrays concurrently, and every entry sums its contributions in colour order whatever the
  // thread count. A tensor-product patch of degree p needs about (p + 1)² colours.
  const auto node_of = [&](size_t e, int a) {
    return static_cast<size_t>(element_nodes_[e * static_cast<size_t>(element_nodes_count_) + static_cast<size_t>(a)]);
  };
  std::vector<std::vector<int>> node_elements(static_cast<size_t>(space_.node_count()));
  for (size_t e = 0; e < elements; ++e) {
    for (int a = 0; a < element_nodes_count_; ++a) node_elements[node_of(e, a)].push_back(static_cast<int>(e));
  }
  std::vector<int> colour(elements, -1);
  colours_.clear();
  for (size_t e = 0; e < elements; ++e) {
    std::vector<bool> taken(colours_.size() + 1, false);
    for (int a = 0; a < element_nodes_count_; ++a) {
      for (const int other : node_elements[node_of(e, a)]) {
        if (colour[static_cast<size_t>(other)] >= 0) taken[static_cast<size_t>(colour[static_cast<size_t>(other)])] = true;
      }
    }
    const auto first_free = static_cast<int>(std::find(taken.begin(), taken.end(), false) - taken.begin());
    colour[e] = first_free;
    if (first_free == static_cast<int>(colours_.size())) colours_.emplace_back();
    colours_[static_cast<size_t>(first_free)].push_back(static_cast<int>(e));
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

void SolidProblem::fix_side(numerics::Side side, int component, double value, TimeFunction scale) {
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

template <int Nen>
void SolidProblem::assemble_element(size_t element, const Eigen::VectorXd& u, double dt, bool with_tangent,
                                    const std::vector<MaterialState>* iterate, Assembly& out,
                                    std::string& failure) const {
  // Sizes fixed at compile time for the common node counts, so that the loops over nodes and the
  // padded row expressions below vectorise.
  using Row = Eigen::Matrix<double, Nen, 1>;
  using Block = Eigen::Matrix<double, Nen, Nen>;
  const int nen = Nen == Eigen::Dynamic ? element_nodes_count_ : Nen;  // a compile-time trip count where possible
  const int* nodes = element_nodes_.data() + element * static_cast<size_t>(nen);
  Row ux(nen), uy(nen);  // the element's nodal displacements
  for (int a = 0; a < nen; ++a) {
    ux(a) = u(2 * nodes[a]);
    uy(a) = u(2 * nodes[a] + 1);
  }
  Row fx = Row::Zero(nen), fy = Row::Zero(nen);
  // The tangent in 2 × 2 blocks of nen × nen, block (i, k) = Σ w gᵀ A_ik g with A_ik(j, l) = ∂S_ij/∂H_kl
  // (δH_kl = δu_k ∂R/∂X_l).
  const int first = element_first_point_[element], points = element_first_point_[element + 1] - first;
  MaterialTangentBlocks<Nen> tangent(nen, points, with_tangent);
  for (int q = 0; q < points; ++q) {
    const auto uk = static_cast<size_t>(first + q);
    tangent.set_gradients(q, point_gradients(uk));
    const double* g0 = tangent.gradient_x(q);
    const double* g1 = tangent.gradient_y(q);
    Eigen::Matrix2d h = Eigen::Matrix2d::Zero();
    for (int a = 0; a < nen; ++a) {
      h(0, 0) += ux(a) * g0[a];
      h(0, 1) += ux(a) * g1[a];
      h(1, 0) += uy(a) * g0[a];
      h(1, 1) += uy(a) * g1[a];
    }
    StressResponse r = material_->update(h, states_[uk], dt, with_tangent, iterate != nullptr ? &(*iterate)[uk] : nullptr);
    if (!r.ok) {
      const auto& point = space_.quadrature()[uk];
      failure = r.reason + " at X = (" + std::to_string(point.position.x()) + ", " + std::to_string(point.position.y()) + ")";
      return;
    }
    const double w = point_weights_[uk];
    const Eigen::Matrix2d ws = w * r.stress;
    for (int a = 0; a < nen; ++a) {  // f_int[a, i] += S_ij ∂R_a/∂X_j w
      fx(a) += ws(0, 0) * g0[a] + ws(0, 1) * g1[a];
      fy(a) += ws(1, 0) * g0[a] + ws(1, 1) * g1[a];
    }
    out.states[uk] = std::move(r.state);
    out.stresses[uk] = r.stress;
    if (with_tangent) tangent.add_point(q, w * r.tangent);
  }
  Block kxx, kxy, kyy;
  if (with_tangent) tangent.blocks(kxx, kxy, kyy);
  for (int a = 0; a < nen; ++a) {
    out.internal(2 * nodes[a]) += fx(a);
    out.internal(2 * nodes[a] + 1) += fy(a);
  }
  if (!with_tangent) return;
  double* values = out.tangent.valuePtr();
  const int* slots = element_slots_[element].data();
  const int n = 2 * nen;
  // Entries above the diagonal have slot −1: the lower triangle is stored.
  const auto add = [values](int slot, double v) {
    if (slot >= 0) values[slot] += v;
  };
  for (int b = 0; b < nen; ++b) {
    for (int a = 0; a < nen; ++a) {
      add(slots[a + n * b], kxx(a, b));
      add(slots[(nen + a) + n * b], kxy(b, a));  // block (y, x) = (x, y)ᵀ
      add(slots[a + n * (nen + b)], kxy(a, b));
      add(slots[(nen + a) + n * (nen + b)], kyy(a, b));
    }
  }
}

template <int Nen>
void SolidProblem::assemble_element_mean_dilatation(size_t element, const Eigen::VectorXd& u, double dt,
                                                    bool with_tangent, const std::vector<MaterialState>* iterate,
                                                    Assembly& out, std::string& failure) const {
  // Flattened 2 × 2 tensors follow the material's order: (0,0), (0,1), (1,0), (1,1).
  // With F̄ = s F, s = (J̄/J)^{1/2}, the virtual work Σ w P̄ : δF̄ becomes Σ w S* : δF with
  // S* = s P̄ + (M̄/J̄ − m/J) cof F, m = ½ P̄ : F̄ and M̄ its element mean (δJ = cof F : δF, and
  // δJ̄ = mean of δJ); the tangent is the derivative of S* (cof is linear in 2D).
  constexpr int kDofs = Nen == Eigen::Dynamic ? Eigen::Dynamic : 2 * Nen;
  using DofRow = Eigen::Matrix<double, 1, kDofs>;
  const int nen = Nen == Eigen::Dynamic ? element_nodes_count_ : Nen;
  const int n = 2 * nen;
  const int* nodes = element_nodes_.data() + element * static_cast<size_t>(nen);
  const int first = element_first_point_[element], points = element_first_point_[element + 1] - first;
  const auto cofactor = [](const Eigen::Vector4d& f) { return Eigen::Vector4d(f(3), -f(2), -f(1), f(0)); };
  // Per-point scratch on the stack when the node count is fixed (points ≤ nodes: build_pattern).
  const auto scratch = [points]<class T>(T) { return PointArray<T, Nen>(static_cast<size_t>(points)); };
  auto f = scratch(Eigen::Vector4d());
  auto h = scratch(Eigen::Vector4d());  // H = F − I
  auto jac = scratch(0.0), jac_minus_one = scratch(0.0), weight = scratch(0.0);
  double volume = 0.0, mean_j_minus_one = 0.0;
  for (int q = 0; q < points; ++q) {
    const auto uk = static_cast<size_t>(first + q);
    const double* g = point_gradients(uk);
    const auto qk = static_cast<size_t>(q);
    h[qk].setZero();
    for (int a = 0; a < nen; ++a) {
      const double ux = u(2 * nodes[a]), uy = u(2 * nodes[a] + 1);
      h[qk](0) += ux * g[a];
      h[qk](1) += ux * g[nen + a];
      h[qk](2) += uy * g[a];
      h[qk](3) += uy * g[nen + a];
    }
    f[qk] = h[qk] + Eigen::Vector4d(1.0, 0.0, 0.0, 1.0);
    // J − 1 from H, not from F = I + H: at small strains 1 + H would round H's digits away.
    jac_minus_one[qk] = h[qk](0) + h[qk](3) + h[qk](0) * h[qk](3) - h[qk](1) * h[qk](2);
    jac[qk] = 1.0 + jac_minus_one[qk];
    if (!(jac[qk] > 0.0)) {
      const auto& point = space_.quadrature()[uk];
      failure = "the chip's deformation inverts an element (det F = " + std::to_string(jac[qk]) + ") at X = (" +
                std::to_string(point.position.x()) + ", " + std::to_string(point.position.y()) + ")";
      return;
    }
    weight[qk] = point_weights_[uk];
    volume += weight[qk];
    mean_j_minus_one += weight[qk] * jac_minus_one[qk];
  }
  mean_j_minus_one /= volume;
  const double mean_j = 1.0 + mean_j_minus_one;
  auto p_bar = scratch(Eigen::Vector4d());
  auto a_bar = scratch(Eigen::Matrix4d());
  auto m = scratch(0.0), s = scratch(0.0);
  double mean_m = 0.0;
  for (int q = 0; q < points; ++q) {
    const auto uk = static_cast<size_t>(first + q);
    const auto qk = static_cast<size_t>(q);
    // s − 1 and H̄ = s H + (s − 1) I written so that no digit of a small H is lost.
    const double ratio_minus_one = (mean_j_minus_one - jac_minus_one[qk]) / jac[qk];
    const double s_minus_one = ratio_minus_one / (std::sqrt(1.0 + ratio_minus_one) + 1.0);
    s[qk] = 1.0 + s_minus_one;
    const Eigen::Vector4d f_bar = s[qk] * f[qk];
    Eigen::Matrix2d h_bar;
    h_bar << s[qk] * h[qk](0) + s_minus_one, s[qk] * h[qk](1), s[qk] * h[qk](2), s[qk] * h[qk](3) + s_minus_one;
    StressResponse r = material_->update(h_bar, states_[uk], dt, with_tangent, iterate != nullptr ? &(*iterate)[uk] : nullptr);
    if (!r.ok) {
      const auto& point = space_.quadrature()[uk];
      failure = r.reason + " at X = (" + std::to_string(point.position.x()) + ", " + std::to_string(point.position.y()) + ")";
      return;
    }
    p_bar[qk] << r.stress(0, 0), r.stress(0, 1), r.stress(1, 0), r.stress(1, 1);
    if (with_tangent) a_bar[qk] = r.tangent;
    m[qk] = 0.5 * p_bar[qk].dot(f_bar);
    mean_m += weight[qk] * m[qk];
    out.states[uk] = std::move(r.state);
  }
  mean_m /= volume;
  // bᵀv for a flattened tensor v, b = ∂F/∂u_e: x dofs move F's first row, y dofs its second, so each
  // column of b has two non-zeros (∂R_a/∂X, ∂R_a/∂Y) and bᵀv costs two passes over the nodes.
  const auto b_transpose = [&](int q, const Eigen::Vector4d& v) {
    const double* g = point_gradients(static_cast<size_t>(first + q));
    DofRow r(n);
    for (int a = 0; a < nen; ++a) {
      r(a) = v(0) * g[a] + v(1) * g[nen + a];
      r(nen + a) = v(2) * g[a] + v(3) * g[nen + a];
    }
    return r;
  };
  for (int q = 0; q < points; ++q) {
    const auto uk = static_cast<size_t>(first + q);
    const auto qk = static_cast<size_t>(q);
    const Eigen::Vector4d effective = s[qk] * p_bar[qk] + (mean_m / mean_j - m[qk] / jac[qk]) * cofactor(f[qk]);
    const DofRow force = weight[qk] * b_transpose(q, effective);
    for (int a = 0; a < nen; ++a) {
      out.internal(2 * nodes[a]) += force(a);
      out.internal(2 * nodes[a] + 1) += force(nen + a);
    }
    out.stresses[uk] << effective(0), effective(1), effective(2), effective(3);
  }
  if (!with_tangent) return;
  // The tangent Σ_q w bᵀ ∂S*/∂u_e, expanded (A = ∂P̄/∂F̄, symmetric; c = M̄/J̄ − m/J; Cof the 4 × 4
  // matrix of cof(·), linear in 2D; δ ln s = ½(δJ̄/J̄ − δJ/J)):
  //   ∂S*/∂u_e = (s²A + c Cof) b + (s p̄ + s² A F) ⊗ δ ln s + cof F ⊗ δc,
  // so k = Σ w bᵀ(s²A + c Cof) b — the displacement element's form with a modified A — plus rank-one
  // terms, summed as one product of stacked rows below. Nothing 4 × n is formed per point.
  DofRow d_mean_j = DofRow::Zero(n);
  auto d_j = scratch(DofRow());  // δJ = cof F : δF
  for (int q = 0; q < points; ++q) {
    const auto qk = static_cast<size_t>(q);
    d_j[qk] = b_transpose(q, cofactor(f[qk]));
    d_mean_j += weight[qk] / volume * d_j[qk];
  }
  auto u_vec = scratch(DofRow()), d_m = scratch(DofRow()), d_log_s = scratch(DofRow());
  DofRow d_mean_m = DofRow::Zero(n), weighted_u_sum = DofRow::Zero(n);
  for (int q = 0; q < points; ++q) {
    const auto qk = static_cast<size_t>(q);
    const Eigen::Vector4d a_f = a_bar[qk] * f[qk];
    d_log_s[qk] = 0.5 * (d_mean_j / mean_j - d_j[qk] / jac[qk]);
    u_vec[qk] = s[qk] * b_transpose(q, p_bar[qk] + s[qk] * a_f);  // bᵀ(s p̄ + s² A F)
    // δm = ½ δ(P̄ : F̄) = ½ [bᵀ(s p̄ + s² A F) + s (s F·A F + p̄·F) δ ln s] (A symmetric)
    d_m[qk] = 0.5 * (u_vec[qk] + s[qk] * (s[qk] * f[qk].dot(a_f) + p_bar[qk].dot(f[qk])) * d_log_s[qk]);
    d_mean_m += weight[qk] / volume * d_m[qk];
    weighted_u_sum += weight[qk] * u_vec[qk];
  }
  // Rank-one terms Σ w u ⊗ δ ln s + Σ w δJ ⊗ δc as left/right rows: per point −½ w/J u ⊗ δJ and
  // w δJ ⊗ (m/J² δJ − δm/J); for the element ½/J̄ (Σ w u) ⊗ δJ̄ and V δJ̄ ⊗ (δM̄/J̄ − M̄/J̄² δJ̄).
  constexpr int kMaxRankRows = Nen == Eigen::Dynamic ? Eigen::Dynamic : 2 * Nen + 2;
  using StackedRows = Eigen::Matrix<double, Eigen::Dynamic, kDofs, Eigen::RowMajor, kMaxRankRows, kDofs>;
  StackedRows left(2 * points + 2, n), right(2 * points + 2, n);
  for (int q = 0; q < points; ++q) {
    const auto qk = static_cast<size_t>(q);
    left.row(2 * q) = -0.5 * weight[qk] / jac[qk] * u_vec[qk];
    right.row(2 * q) = d_j[qk];
    left.row(2 * q + 1) = weight[qk] * d_j[qk];
    right.row(2 * q + 1) = m[qk] / (jac[qk] * jac[qk]) * d_j[qk] - d_m[qk] / jac[qk];
  }
  left.row(2 * points) = 0.5 / mean_j * weighted_u_sum;
  right.row(2 * points) = d_mean_j;
  left.row(2 * points + 1) = volume * d_mean_j;
  right.row(2 * points + 1) = d_mean_m / mean_j - mean_m / (mean_j * mean_j) * d_mean_j;
  // Lazy (coefficient-wise) products here and below: at these sizes Eigen's GEMM path spent more time
  // packing its operands than multiplying (perf, bench/studies/friction_laws/README.md).
  Eigen::Matrix<double, kDofs, kDofs> k(n, n);
  k.noalias() = left.transpose().lazyProduct(right);
  // Σ w bᵀ Ã b, Ã = s²A + c Cof: the displacement element's blocks with a modified material matrix.
  MaterialTangentBlocks<Nen> tangent(nen, points, true);
  Eigen::Matrix4d cofactor_matrix;
  cofactor_matrix << 0, 0, 0, 1, 0, 0, -1, 0, 0, -1, 0, 0, 1, 0, 0, 0;
  for (int q = 0; q < points; ++q) {
    const auto qk = static_cast<size_t>(q);
    tangent.set_gradients(q, point_gradients(static_cast<size_t>(first + q)));
    tangent.add_point(q, weight[qk] * (s[qk] * s[qk] * a_bar[qk] + (mean_m / mean_j - m[qk] / jac[qk]) * cofactor_matrix));
  }
  typename MaterialTangentBlocks<Nen>::Block kxx, kxy, kyy;
  tangent.blocks(kxx, kxy, kyy);
  k.topLeftCorner(nen, nen) += kxx;
  k.topRightCorner(nen, nen) += kxy;
  k.bottomLeftCorner(nen, nen) += kxy.transpose();  // Ã symmetric: block (y, x) = (x, y)ᵀ
  k.bottomRightCorner(nen, nen) += kyy;
  scatter_element_tangent(element, k.data(), n, out);
}

void SolidProblem::scatter_element_tangent(size_t element, const double* k, int n, Assembly& out) const {
  double* values = out.tangent.valuePtr();
  const int* slots = element_slots_[element].data();
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) {
      const int slot = slots[r + n * c];
      if (slot >= 0) values[slot] += k[r + n * c];  // −1: above the diagonal, the lower triangle is stored
    }
  }
}

SolidProblem::Assembly SolidProblem::assemble(const Eigen::VectorXd& u, double dt, bool with_tangent,
                                              const std::vector<MaterialState>* iterate) const {
  if (iterate != nullptr && iterate->size() != states_.size()) iterate = nullptr;  // not this problem's
  Assembly out;
  out.internal = Eigen::VectorXd::Zero(dof_count());
  out.states.resize(states_.size());
  out.stresses.resize(states_.size());
  if (with_tangent) out.tangent = MovableSparseMatrix(pattern_);
  const size_t elements = element_first_point_.size() - 1;
  std::vector<std::string> failure(elements);
  const auto kernel = [&](size_t e) {
    if (volumetric_ == VolumetricTreatment::mean_dilatation) {
      switch (element_nodes_count_) {
        case 9: return assemble_element_mean_dilatation<9>(e, u, dt, with_tangent, iterate, out, failure[e]);
        default: return assemble_element_mean_dilatation<Eigen::Dynamic>(e, u, dt, with_tangent, iterate, out, failure[e]);
      }
    }
    switch (element_nodes_count_) {
      case 4: return assemble_element<4>(e, u, dt, with_tangent, iterate, out, failure[e]);
      case 9: return assemble_element<9>(e, u, dt, with_tangent, iterate, out, failure[e]);
      case 16: return assemble_element<16>(e, u, dt, with_tangent, iterate, out, failure[e]);
      default: return assemble_element<Eigen::Dynamic>(e, u, dt, with_tangent, iterate, out, failure[e]);
    }
  };
  for (const auto& colour : colours_) {
    const auto count = static_cast<long>(colour.size());
#pragma omp parallel for schedule(dynamic, 16)
    for (long i = 0; i < count; ++i) kernel(static_cast<size_t>(colour[static_cast<size_t>(i)]));
  }
  for (const auto& reason : failure) {
    if (!reason.empty()) {
      out.ok = false;
      out.reason = reason;
      return out;
    }
  }
  // Every element succeeded (a failure returned above): the boundary interactions come on top.
  const auto start = std::chrono::steady_clock::now();
  const numerics::MatrixStorage storage = tangent_storage();
  if (with_tangent && storage == numerics::MatrixStorage::full) {
    out.tangent = MovableSparseMatrix(SparseMatrix(out.tangent.selfadjointView<Eigen::Lower>()));
  }
  TangentAccumulator accumulator(out.tangent, storage);
  for (const auto& interaction : interactions_) {
    accumulator.begin_interaction();
    if (!interaction->add(u, out.internal, with_tangent ? &accumulator : nullptr, out.reason)) {
      out.ok = false;
      break;
    }
    if (const auto why = accumulator.asymmetry()) {
      // A programming error, not a hard step: the lower triangle kept would be another matrix.
      throw Error("tangent: a boundary interaction that declares a symmetric tangent added an unsymmetric one (" + *why +
                  "); it must say symmetric_tangent() false");
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

const SparseMatrix& SolidProblem::mass(numerics::MatrixStorage storage) const {
  if (storage == numerics::MatrixStorage::full) {
    // The same mirror of the same lower pattern as a full tangent's: equal patterns, added by value.
    if (full_mass_.nonZeros() == 0) full_mass_ = mass().selfadjointView<Eigen::Lower>();
    return full_mass_;
  }
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
          for (int i = 0; i < 2; ++i) {
            const int slot = slots[static_cast<size_t>((i * nen + a) + n * (i * nen + b))];
            if (slot >= 0) values[slot] += m;
          }
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
