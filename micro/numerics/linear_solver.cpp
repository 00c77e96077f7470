#include "micro/numerics/linear_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/UmfPackSupport>
#include <omp.h>

#include <mutex>
#include <vector>

#include "common/error.hpp"

namespace mufric::numerics {
namespace {

// Debian's CHOLMOD 3 (SuiteSparse 5) opens OpenMP teams of a compiled-in 4 threads in its supernodal
// numeric factorisation (num_threads(CHOLMOD_OMP_NUM_THREADS), whatever OMP_NUM_THREADS says). With
// fewer threads granted to us that oversubscribes the cores: a one-core run spent a quarter of its
// time waking and parking those threads, and the factorisation took 1.7× UMFPACK's time instead of
// less. Below that many threads, the factorisation runs with parallel regions made inactive.
constexpr int kCholmodTeamThreads = 4;

class CholmodThreadsWithinOurs {
 public:
  CholmodThreadsWithinOurs() : previous_levels_(omp_get_max_active_levels()), limit_(omp_get_max_threads() < kCholmodTeamThreads) {
    if (limit_) omp_set_max_active_levels(0);
  }
  ~CholmodThreadsWithinOurs() {
    if (limit_) omp_set_max_active_levels(previous_levels_);
  }
  CholmodThreadsWithinOurs(const CholmodThreadsWithinOurs&) = delete;
  CholmodThreadsWithinOurs& operator=(const CholmodThreadsWithinOurs&) = delete;

 private:
  int previous_levels_;
  bool limit_;
};

// METIS keeps its random state in a global (GKlib's generator) and reseeds it at the start of each
// ordering: two draws ordering their patterns at once drew from one sequence in turns, so their
// orderings, and μ's last digits with them, changed from run to run with draws side by side. One
// ordering at a time; it runs once per pattern, against hundreds of factorisations.
std::mutex ordering_mutex;

using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Cholesky = Eigen::CholmodSupernodalLLT<Sparse>;

// BiCGSTAB's relative residual for an unsymmetric tangent: Newton's own tolerance is 1e-9 of the
// force scale, so 1e-12 of the right-hand side keeps its iterations those of an exact solve.
constexpr double kKrylovTolerance = 1e-12;
// Beyond this many iterations the skew part is not small: LU instead (a few are typical).
constexpr int kKrylovMaxIterations = 40;

// Eigen's preconditioner interface over a Cholesky factor computed elsewhere (the symmetric part's).
class FactorPreconditioner {
 public:
  FactorPreconditioner() = default;
  template <typename M>
  explicit FactorPreconditioner(const M&) {}
  template <typename M>
  FactorPreconditioner& analyzePattern(const M&) { return *this; }
  template <typename M>
  FactorPreconditioner& factorize(const M&) { return *this; }
  template <typename M>
  FactorPreconditioner& compute(const M&) { return *this; }
  template <typename Rhs>
  Eigen::VectorXd solve(const Rhs& b) const { return factor_->solve(Eigen::VectorXd(b)); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }
  void use(const Cholesky* factor) { factor_ = factor; }

 private:
  const Cholesky* factor_ = nullptr;
};

}  // namespace

struct LinearSolver::Impl {
  Eigen::UmfPackLU<Sparse> lu;
  Cholesky cholesky;
  std::vector<int> outer, inner;  // pattern of the last analysis
  Sparse full;  // LU of a lower-stored matrix: both triangles
  Sparse unsymmetric;  // the unsymmetric matrix whose symmetric part `cholesky` holds
  Eigen::BiCGSTAB<Sparse, FactorPreconditioner> krylov;
};

LinearSolver::LinearSolver(LinearSolverKind kind) : impl_(std::make_unique<Impl>()), kind_(kind) {
  // The tangents are structurally symmetric (and, in the default scene, symmetric in value to
  // round-off; LU keeps the solver general): UMFPACK's symmetric strategy (AMD on A + Aᵀ, diagonal
  // pivots preferred; Davis, ACM TOMS 30(2) 2004, sec. 2) suits them better than its column ordering.
  impl_->lu.umfpackControl()(UMFPACK_STRATEGY) = UMFPACK_STRATEGY_SYMMETRIC;
  // No iterative refinement inside the solve: each Newton iteration already refines the solution,
  // and every refinement step is another solve plus a matrix-vector product.
  impl_->lu.umfpackControl()(UMFPACK_IRSTEP) = 0;
  // A matrix that is not positive definite is an answer here (LU takes it), not a warning for stderr.
  impl_->cholesky.cholmod().print = 0;
  // The pattern is analysed once per run and factorised hundreds of times: try AMD, METIS and
  // CHOLMOD's nested dissection and keep the least fill (CHOLMOD's default tries METIS only when AMD's
  // fill looks bad). On the 128 x 24 chip METIS needs 25 % fewer flops than AMD: 16.3 vs 17.4 ms per
  // factorisation.
  auto& common = impl_->cholesky.cholmod();
  common.nmethods = 3;
  common.method[0].ordering = CHOLMOD_AMD;
  common.method[1].ordering = CHOLMOD_METIS;
  common.method[2].ordering = CHOLMOD_NESDIS;
}
LinearSolver::~LinearSolver() = default;
LinearSolver::LinearSolver(LinearSolver&&) noexcept = default;
LinearSolver& LinearSolver::operator=(LinearSolver&&) noexcept = default;

bool LinearSolver::factorize(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, MatrixStorage storage,
                             Symmetry symmetry) {
  if (symmetry == Symmetry::unsymmetric && storage == MatrixStorage::lower_symmetric) {
    throw Error("linear solver: an unsymmetric matrix cannot be given by its lower triangle");
  }
  const bool same_pattern =
      analyses_ > 0 && static_cast<Eigen::Index>(impl_->outer.size()) == a.outerSize() + 1 &&
      static_cast<Eigen::Index>(impl_->inner.size()) == a.nonZeros() &&
      std::equal(impl_->outer.begin(), impl_->outer.end(), a.outerIndexPtr()) &&
      std::equal(impl_->inner.begin(), impl_->inner.end(), a.innerIndexPtr());
  if (!same_pattern) {
    impl_->outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1);
    impl_->inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
    lu_analysed_ = cholesky_analysed_ = false;
    ++analyses_;
  }
  reason_.clear();
  if (kind_ == LinearSolverKind::lu) return factorize_lu(a, storage);
  if (symmetry == Symmetry::unsymmetric) {
    impl_->unsymmetric = a;
    const Sparse symmetric_part = 0.5 * (a + Sparse(a.transpose()));
    if (factorize_cholesky(symmetric_part)) {
      method_ = Method::preconditioned_krylov;
      impl_->krylov.setMaxIterations(kKrylovMaxIterations);
      impl_->krylov.compute(impl_->unsymmetric);
      impl_->krylov.preconditioner().use(&impl_->cholesky);
      return true;
    }
  } else if (factorize_cholesky(a)) {
    method_ = Method::cholesky;
    return true;
  }
  ++lu_fallbacks_;
  if (factorize_lu(a, storage)) return true;
  reason_ = "CHOLMOD: the tangent" + std::string(symmetry == Symmetry::unsymmetric ? "'s symmetric part" : "") +
            " is not positive definite, and " + reason_;
  return false;
}

bool LinearSolver::factorize_cholesky(const Sparse& a) const {
  const CholmodThreadsWithinOurs threads;
  if (!cholesky_analysed_) {
    const std::lock_guard one_ordering_at_a_time(ordering_mutex);
    impl_->cholesky.analyzePattern(a);
    cholesky_analysed_ = true;
  }
  impl_->cholesky.factorize(a);
  return impl_->cholesky.info() == Eigen::Success;
}

bool LinearSolver::factorize_lu(const Sparse& a, MatrixStorage storage) const {
  if (storage == MatrixStorage::lower_symmetric) impl_->full = a.selfadjointView<Eigen::Lower>();
  const auto& m = storage == MatrixStorage::lower_symmetric ? impl_->full : a;
  if (!lu_analysed_) {
    impl_->lu.analyzePattern(m);
    lu_analysed_ = true;
  }
  impl_->lu.factorize(m);
  if (impl_->lu.info() != Eigen::Success) {
    reason_ = "UMFPACK: the tangent is singular";
    return false;
  }
  method_ = Method::lu;
  return true;
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& b, double relative_tolerance) const {
  switch (method_) {
    case Method::cholesky:
      return impl_->cholesky.solve(b);
    case Method::lu:
      return impl_->lu.solve(b);
    case Method::preconditioned_krylov:
      break;
  }
  auto& krylov = impl_->krylov;
  krylov.setTolerance(relative_tolerance > 0.0 ? relative_tolerance : kKrylovTolerance);
  Eigen::VectorXd x = krylov.solveWithGuess(b, Eigen::VectorXd(impl_->cholesky.solve(b)));
  krylov_iterations_ += static_cast<int>(krylov.iterations());
  if (krylov.info() == Eigen::Success) return x;
  // The skew part is not small here: this matrix by LU, and its later solves too. (If even LU fails,
  // the iteration's last iterate goes back: Newton's residual check judges it, and a step that does
  // not converge is cut back.)
  ++lu_fallbacks_;
  if (!factorize_lu(impl_->unsymmetric, MatrixStorage::full)) return x;
  return impl_->lu.solve(b);
}

}  // namespace mufric::numerics
