#pragma once
// Sparse direct solves through Eigen's SuiteSparse modules: UMFPACK's LU for general tangents,
// CHOLMOD's supernodal Cholesky for symmetric positive definite ones. A Cholesky solver that meets a
// matrix CHOLMOD finds not positive definite factorises that one by LU instead (and counts it), so
// choosing Cholesky for a tangent that is SPD in practice never costs a failed step.
// The symbolic analysis is done once for a sparsity pattern and reused by every factorisation.
#include <memory>
#include <string>

#include <Eigen/Sparse>

#include "micro/settings/option_keys.hpp"

namespace mufric::numerics {

enum class LinearSolverKind { lu, cholesky };
// How a matrix given to the solver is stored: every entry, or the lower triangle of a symmetric
// matrix (SolidProblem's tangents and mass matrices).
enum class MatrixStorage { full, lower_symmetric };
// Whether a matrix is symmetric in value (a frictional contact's tangent is not, Wriggers 2006, ch. 5:
// slip makes it unsymmetric). A Cholesky solver given an unsymmetric matrix A factorises its
// symmetric part (A + Aᵀ)/2 and solves A by BiCGSTAB preconditioned with that factor (Concus & Golub
// 1976, the symmetric part as preconditioner of a nearly symmetric system; van der Vorst 1992,
// BiCGSTAB): friction's skew part is small beside the chip's stiffness, so a few iterations do, at a
// Cholesky's cost instead of an LU's. If the symmetric part is not positive definite, or the
// iteration does not converge, A is factorised by LU (counted as a fallback).
enum class Symmetry { symmetric, unsymmetric };

class LinearSolver {
 public:
  explicit LinearSolver(LinearSolverKind kind = LinearSolverKind::lu);
  ~LinearSolver();
  LinearSolver(LinearSolver&&) noexcept;
  LinearSolver& operator=(LinearSolver&&) noexcept;
  // Factorises A (re-analysing only when its pattern differs from the last one). false: singular
  // or not positive definite; `reason()` says which. An unsymmetric matrix must be stored full.
  bool factorize(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, MatrixStorage storage = MatrixStorage::full,
                 Symmetry symmetry = Symmetry::symmetric);
  // A's solution; an unsymmetric matrix given to a Cholesky solver falls back to LU here if the
  // preconditioned iteration does not converge.
  // relative_tolerance: the residual ‖b − A x‖/‖b‖ an iterative solve may leave (Newton's forcing
  // term); 0 for the solver's own (1e-12). Direct solves ignore it.
  Eigen::VectorXd solve(const Eigen::VectorXd& b, double relative_tolerance = 0.0) const;
  // Whether a matrix of this symmetry is factorised by LU (an LU solver); a Cholesky solver's LU
  // fallbacks are not foreseen here.
  bool factorizes_by_lu(Symmetry) const { return kind_ == LinearSolverKind::lu; }
  const std::string& reason() const { return reason_; }
  int analyses() const { return analyses_; }  // symbolic analyses done so far
  int lu_fallbacks() const { return lu_fallbacks_; }  // Cholesky solver: matrices factorised by LU instead
  int krylov_iterations() const { return krylov_iterations_; }  // BiCGSTAB iterations over all solves

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LinearSolverKind kind_;
  mutable std::string reason_;
  int analyses_ = 0;
  mutable int lu_fallbacks_ = 0;
  mutable int krylov_iterations_ = 0;
  enum class Method { cholesky, lu, preconditioned_krylov };
  mutable Method method_ = Method::cholesky;  // how `solve` solves the last factorised matrix
  mutable bool lu_analysed_ = false, cholesky_analysed_ = false;  // for the current pattern
  bool factorize_lu(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, MatrixStorage storage) const;
  bool factorize_cholesky(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a) const;
};

}  // namespace mufric::numerics

MUFRIC_OPTION_WORDS(numerics::LinearSolverKind, {"lu", numerics::LinearSolverKind::lu},
                    {"cholesky", numerics::LinearSolverKind::cholesky})
