#pragma once
// Sparse direct solves through Eigen's SuiteSparse modules: UMFPACK's LU for general tangents,
// CHOLMOD's supernodal Cholesky for symmetric positive definite ones. A Cholesky solver that meets a
// matrix CHOLMOD finds not positive definite factorises that one by LU instead (and counts it), so
// choosing Cholesky for a tangent that is SPD in practice never costs a failed step.
// The symbolic analysis is done once for a sparsity pattern and reused by every factorisation.
#include <memory>
#include <string>

#include <Eigen/Sparse>

namespace mufric::numerics {

enum class LinearSolverKind { lu, cholesky };
// How a matrix given to the solver is stored: every entry, or the lower triangle of a symmetric
// matrix (SolidProblem's tangents and mass matrices).
enum class MatrixStorage { full, lower_symmetric };
// Whether a matrix is symmetric in value. A Cholesky solver factorises an unsymmetric one by LU (a
// frictional contact's tangent, Wriggers 2006, ch. 5: slip makes it unsymmetric).
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
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Whether a matrix of this symmetry is factorised by LU (an LU solver, or any unsymmetric matrix);
  // a Cholesky solver's LU fallback for a matrix not positive definite is not foreseen here.
  bool factorizes_by_lu(Symmetry symmetry) const { return kind_ == LinearSolverKind::lu || symmetry == Symmetry::unsymmetric; }
  const std::string& reason() const { return reason_; }
  int analyses() const { return analyses_; }  // symbolic analyses done so far
  int lu_fallbacks() const { return lu_fallbacks_; }  // Cholesky solver: matrices factorised by LU instead

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LinearSolverKind kind_;
  std::string reason_;
  int analyses_ = 0;
  int lu_fallbacks_ = 0;
  bool last_by_lu_ = false;  // which factorisation `solve` uses
  bool lu_analysed_ = false, cholesky_analysed_ = false;  // for the current pattern
  bool factorize_lu(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, MatrixStorage storage);
};

}  // namespace mufric::numerics
