#pragma once
// Sparse direct solves through Eigen's SuiteSparse modules: UMFPACK's LU for general (e.g.
// plastic, contact) tangents, CHOLMOD's supernodal Cholesky for symmetric positive definite ones.
// The symbolic analysis is done once for a sparsity pattern and reused by every factorisation.
#include <memory>
#include <string>

#include <Eigen/Sparse>

namespace mufric::solid {

enum class LinearSolverKind { lu, cholesky };

class LinearSolver {
 public:
  explicit LinearSolver(LinearSolverKind kind = LinearSolverKind::lu);
  ~LinearSolver();
  LinearSolver(LinearSolver&&) noexcept;
  LinearSolver& operator=(LinearSolver&&) noexcept;
  // Factorises A (re-analysing only when its pattern differs from the last one). false: singular
  // or not positive definite; `reason()` says which.
  bool factorize(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a);
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  const std::string& reason() const { return reason_; }
  int analyses() const { return analyses_; }  // symbolic analyses done so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LinearSolverKind kind_;
  std::string reason_;
  int analyses_ = 0;
};

}  // namespace mufric::solid
