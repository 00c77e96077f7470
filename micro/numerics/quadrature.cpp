#include "micro/numerics/quadrature.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace mufric::numerics {

void gauss_legendre(int count, std::vector<double>& nodes, std::vector<double>& weights) {
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(count, count);
  for (int k = 1; k < count; ++k) {
    jacobi(k, k - 1) = jacobi(k - 1, k) = k / std::sqrt(4.0 * k * k - 1.0);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jacobi);
  nodes.resize(static_cast<size_t>(count));
  weights.resize(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) {
    nodes[static_cast<size_t>(k)] = eigen.eigenvalues()(k);
    weights[static_cast<size_t>(k)] = 2.0 * eigen.eigenvectors()(0, k) * eigen.eigenvectors()(0, k);
  }
}

}  // namespace mufric::numerics
