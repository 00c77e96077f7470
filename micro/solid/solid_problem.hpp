#pragma once
// The chip as a boundary-value problem: one IGA patch, one material, Dirichlet conditions on
// control-point displacement components and dead tractions on sides, each scaled by a function of
// time. Assembles internal forces, the tangent (a fixed sparsity pattern, filled element by
// element), external forces and the consistent mass matrix. The mass matrix and, while every boundary
// interaction's tangent is symmetric (frictionless contact, dead nodal loads), the tangent are stored
// as their lower triangle (row ≥ column): products go through selfadjointView<Eigen::Lower>(), and
// CHOLMOD reads that triangle anyway — storing only it halves the scatter, the copies and CHOLMOD's
// transpose of every factorisation. An interaction with an unsymmetric tangent (friction: slip makes
// it so) switches the tangent to full storage: the bulk, symmetric, is assembled into the lower
// triangle as always and mirrored once per assembly, then the interactions add every entry.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Sparse>

#include "micro/numerics/linear_solver.hpp"
#include "micro/solid/iga_space.hpp"
#include "micro/solid/materials.hpp"

namespace mufric::solid {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Eigen 3.4's SparseMatrix has no move operations: std::move of one deep-copies it (4 MB for the
// tangent of the 128 × 24 chip, several times per Newton iteration: 5 % of a run). This one moves
// by swapping.
class MovableSparseMatrix : public SparseMatrix {
 public:
  MovableSparseMatrix() = default;
  explicit MovableSparseMatrix(const SparseMatrix& m) : SparseMatrix(m) {}
  MovableSparseMatrix(const MovableSparseMatrix&) = default;
  MovableSparseMatrix(MovableSparseMatrix&& other) noexcept { swap(other); }
  MovableSparseMatrix& operator=(const MovableSparseMatrix&) = default;
  MovableSparseMatrix& operator=(MovableSparseMatrix&& other) noexcept {
    swap(other);
    return *this;
  }
  ~MovableSparseMatrix() = default;
};
using TimeFunction = std::function<double(double)>;  // scale of a boundary condition at time t

// How the element treats the volume change. `full`: every quadrature point takes its own F (the
// displacement formulation; seed 000's). `mean_dilatation`: the F-bar method with the element's mean
// dilatation (de Souza Neto, Perić, Dutko & Owen, Int. J. Solids Struct. 33:3277, 1996): each point's
// F is replaced by F̄ = (J̄/J)^{1/2} F (plane strain), J̄ the element's reference-volume average of
// det F, so that an isochoric plastic flow meets one volume constraint per element instead of one per
// quadrature point (a C¹ quadratic patch has two displacement dofs per element against nine points:
// the displacement formulation locks in fully plastic flow; Elguedj, Bazilevs, Calo & Hughes, CMAME
// 197:2732, 2008, who project J onto a lower-order spline space instead of the element mean).
enum class VolumetricTreatment { full, mean_dilatation };

struct DirichletCondition {
  int node = 0, component = 0;  // component 0: x, 1: y
  double value = 0.0;           // m, multiplied by scale(t)
  TimeFunction scale;           // empty: 1
};

struct SideLoad {
  numerics::Side side = numerics::Side::top;
  Eigen::Vector2d traction = Eigen::Vector2d::Zero();  // N/m² (force per reference length and unit depth)
  double pressure = 0.0;  // Pa, acting against the reference outward normal (dead load)
  TimeFunction scale;     // empty: 1
};

// Forces on the boundary that depend on the displacement: added to the internal forces and the
// tangent by SolidProblem::assemble. Implemented above solid/: contact/MortarContact (the rough
// tool) and coupling/NodalLoad (the lubricant's tractions on the chip).
class BoundaryInteraction {
 public:
  virtual ~BoundaryInteraction() = default;
  // Groups of nodes whose dofs may couple in the tangent (each group is coupled all-to-all); used
  // once, to extend the sparsity pattern.
  virtual std::vector<std::vector<int>> coupled_nodes() const = 0;
  // Adds the interaction's force (same sign convention as f_int: the residual is f_int + f − f_ext)
  // and, when `tangent` is not null, its derivative. Returns false with a reason on failure.
  virtual bool add(const Eigen::VectorXd& u, Eigen::VectorXd& force, class TangentAccumulator* tangent,
                   std::string& reason) const = 0;
  // Whether the tangent it adds is symmetric: then it adds full symmetric blocks, of which the
  // accumulator keeps the lower triangle; otherwise every entry it adds is kept.
  virtual bool symmetric_tangent() const { return true; }
  // Called with the displacement of every accepted step: an interaction with history (friction's
  // anchors) commits it here, as the material commits its states; a rejected trial never reaches it.
  virtual void commit(const Eigen::VectorXd& /*u*/) {}
};

// Adds entries to a tangent whose pattern already holds them. A tangent stored as its lower triangle
// drops an entry above the diagonal (symmetric interactions add its mirror image as well); one
// stored full keeps every entry. What it drops it still checks: the off-diagonal entries added since
// begin_interaction(), each weighted by a pseudo-random weight of its unordered index pair, sum
// alike above and below the diagonal when the interaction's tangent is symmetric (a missing or
// different mirror image shows as a difference, whatever the other entries).
class TangentAccumulator {
 public:
  TangentAccumulator(Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix, numerics::MatrixStorage storage)
      : matrix_(matrix), storage_(storage) {}
  void add(int row, int col, double value);
  void begin_interaction() { upper_ = lower_ = magnitude_ = 0.0; }
  // With lower-triangle storage: why the entries since begin_interaction() are not symmetric (their
  // weighted sums above and below the diagonal differ by more than kSymmetryTolerance of their
  // size); none when they are, or when the tangent is stored full.
  std::optional<std::string> asymmetry() const;

 private:
  Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix_;
  numerics::MatrixStorage storage_;
  double upper_ = 0.0, lower_ = 0.0, magnitude_ = 0.0;
};
// Rounding alone: a mirror image computed in another order differs by ~1e-16 of its size.
inline constexpr double kSymmetryTolerance = 1e-10;

class SolidProblem {
 public:
  SolidProblem(IgaSpace space, std::shared_ptr<const Material> material,
               MaterialState initial_state = MaterialState(),
               VolumetricTreatment volumetric = VolumetricTreatment::full);

  const IgaSpace& space() const { return space_; }
  const Material& material() const { return *material_; }
  VolumetricTreatment volumetric() const { return volumetric_; }
  int dof_count() const { return space_.dof_count(); }

  void add_dirichlet(DirichletCondition condition);
  // Every control point of a side, one component.
  void fix_side(numerics::Side side, int component, double value = 0.0, TimeFunction scale = {});
  void add_load(SideLoad load);
  // Displacement-dependent boundary forces (contact). Rebuilds the sparsity pattern.
  void add_interaction(std::shared_ptr<BoundaryInteraction> interaction);
  // Symmetric unless an interaction's tangent is not; then the tangent is stored full.
  numerics::Symmetry tangent_symmetry() const;
  numerics::MatrixStorage tangent_storage() const;
  const std::vector<DirichletCondition>& dirichlet() const { return dirichlet_; }
  // true for each dof that carries a Dirichlet condition
  const std::vector<bool>& constrained() const { return constrained_; }
  // Prescribed values at time t written into u (other entries untouched).
  void apply_dirichlet(double t, Eigen::VectorXd& u) const;
  // Rows and columns of constrained dofs become identity rows and columns (symmetry kept), so a
  // Newton increment leaves those dofs at their prescribed values.
  void constrain(SparseMatrix& matrix) const;
  // Zeroes the entries of constrained dofs (a right-hand side for the constrained matrix).
  void zero_constrained(Eigen::VectorXd& vector) const;

  struct Assembly {
    Eigen::VectorXd internal;           // f_int(u)
    MovableSparseMatrix tangent;        // ∂f_int/∂u (when requested), stored as tangent_storage() says
    std::vector<MaterialState> states;  // trial states at u
    std::vector<Eigen::Matrix2d> stresses;  // S at each quadrature point
    bool ok = true;
    std::string reason;
    double seconds_interactions = 0.0;  // of which contact and other boundary interactions
  };
  // Internal forces at u from the committed states (step length dt for rates); never commits.
  // `iterate`: the states of the previous Newton iterate of the same step, as first guesses for the
  // material updates (null: none).
  Assembly assemble(const Eigen::VectorXd& u, double dt, bool with_tangent,
                    const std::vector<MaterialState>* iterate = nullptr) const;
  Eigen::VectorXd external(double t) const;
  // Consistent, ∫ρ R_a R_b dX, built on first use; lower triangle, or full with the tangent's pattern
  // when that is stored full (an inertia term is added to the tangent value by value).
  const SparseMatrix& mass(numerics::MatrixStorage storage = numerics::MatrixStorage::lower_symmetric) const;

  const std::vector<MaterialState>& states() const { return states_; }
  void commit(std::vector<MaterialState> states) { states_ = std::move(states); }
  // The boundary interactions' history at an accepted displacement.
  void commit_interactions(const Eigen::VectorXd& u);
  // Strain energy ½ uᵀ f_int for linear elastic problems (energy checks).
  double elastic_energy(const Eigen::VectorXd& u) const;

 private:
  void build_pattern();
  // One element's forces and tangent, added straight into `out` (elements of one colour share no
  // dof, so a colour's elements may run in parallel). Nen: functions per element, fixed at compile
  // time for the common degrees so that the small products vectorise.
  template <int Nen>
  void assemble_element(size_t element, const Eigen::VectorXd& u, double dt, bool with_tangent,
                        const std::vector<MaterialState>* iterate, Assembly& out, std::string& failure) const;
  // The same with F̄ (VolumetricTreatment::mean_dilatation): forces and tangent are the exact
  // derivatives of Σ_q w_q W(F̄_q), so the tangent stays symmetric.
  template <int Nen>
  void assemble_element_mean_dilatation(size_t element, const Eigen::VectorXd& u, double dt, bool with_tangent,
                                        const std::vector<MaterialState>* iterate, Assembly& out,
                                        std::string& failure) const;
  // Quadrature point k's ∂R/∂X and ∂R/∂Y, a 2 × element_nodes_count_ row-major block.
  const double* point_gradients(size_t k) const { return point_gradients_.data() + k * 2 * static_cast<size_t>(element_nodes_count_); }
  // Scatters an element's n × n tangent (column-major, local dofs component-major) into the lower triangle.
  void scatter_element_tangent(size_t element, const double* k, int n, Assembly& out) const;
  IgaSpace space_;
  std::shared_ptr<const Material> material_;
  VolumetricTreatment volumetric_ = VolumetricTreatment::full;
  std::vector<MaterialState> states_;  // one per quadrature point, committed
  std::vector<DirichletCondition> dirichlet_;
  std::vector<bool> constrained_;
  std::vector<SideLoad> loads_;
  std::vector<std::vector<BoundaryPoint>> load_points_;  // quadrature of each load's side, computed once
  std::vector<std::shared_ptr<BoundaryInteraction>> interactions_;
  SparseMatrix pattern_;                       // structure of the tangent's lower triangle, values zero
  // Per element, local dofs are numbered component-major: x of each of its nodes, then y.
  std::vector<std::vector<int>> element_slots_;  // per element: value index of each local (row, col); −1 above the diagonal
  std::vector<std::vector<int>> element_dofs_;
  std::vector<int> element_first_point_;       // quadrature points of element e: [first[e], first[e+1])
  int element_nodes_count_ = 0;                // functions per element (the same for every element)
  std::vector<int> element_nodes_;             // element e's nodes at [e·count, (e+1)·count)
  std::vector<double> point_gradients_;        // per quadrature point, ∂R/∂X as a 2 × count row-major block
  std::vector<double> point_weights_;          // per quadrature point, weight × |det J|
  std::vector<std::vector<int>> colours_;      // elements grouped so that no two in a group share a node
  mutable SparseMatrix mass_, full_mass_;
};

}  // namespace mufric::solid
