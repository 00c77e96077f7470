#include "micro/fluid/mesh_update.hpp"

#include <cmath>

#include <Eigen/Sparse>

#include "common/error.hpp"

namespace mufric::fluid {

MeshUpdate::MeshUpdate(MeshUpdateOptions options) : options_(options) {
  if (options_.stiffening_exponent < 0.0) throw Error("mesh update: the stiffening exponent must not be negative");
  if (!(options_.poisson_ratio > -1.0 && options_.poisson_ratio < 0.5)) {
    throw Error("mesh update: the mesh Poisson ratio must lie in (-1, 0.5)");
  }
}

MeshMoveReport MeshUpdate::move(FluidSpace& space, const std::vector<std::pair<int, Eigen::Vector2d>>& prescribed) {
  MeshMoveReport report;
  const int dofs = 2 * space.node_count();
  std::vector<char> fixed(static_cast<size_t>(dofs), 0);
  Eigen::VectorXd increment = Eigen::VectorXd::Zero(dofs);
  for (const auto& [node, value] : prescribed) {
    if (node < 0 || node >= space.node_count()) throw Error("mesh update: prescribed node out of range");
    for (int k = 0; k < 2; ++k) fixed[static_cast<size_t>(2 * node + k)] = 1, increment(2 * node + k) = value(k);
  }
  // Plane-strain Lamé constants of a unit-modulus material; only ratios matter.
  const double nu = options_.poisson_ratio;
  const double lambda = nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = 1.0 / (2.0 * (1.0 + nu));
  // J_ref: the mean Gauss-point Jacobian, so the factors are O(1).
  std::vector<PhysicalPoint> points;
  double mean_det = 0.0;
  for (int e = 0; e < space.element_count(); ++e) {
    for (const auto& p : space.element_points(e)) {
      points.push_back(space.map(p));
      mean_det += std::abs(points.back().jacobian.determinant());
    }
  }
  mean_det /= static_cast<double>(points.size());
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(dofs);
  size_t k = 0;
  for (int e = 0; e < space.element_count(); ++e) {
    const std::vector<int>& nodes = space.element_nodes(e);
    const auto n = static_cast<Eigen::Index>(nodes.size());
    Eigen::MatrixXd ke = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    for (size_t g = 0; g < space.element_points(e).size(); ++g, ++k) {
      const PhysicalPoint& q = points[k];
      const double stiffening = std::pow(mean_det / std::abs(q.jacobian.determinant()), options_.stiffening_exponent);
      // B-matrix rows: ε_xx, ε_yy, 2ε_xy.
      Eigen::MatrixXd b = Eigen::MatrixXd::Zero(3, 2 * n);
      for (Eigen::Index a = 0; a < n; ++a) {
        b(0, 2 * a) = q.gradients(0, a);
        b(1, 2 * a + 1) = q.gradients(1, a);
        b(2, 2 * a) = q.gradients(1, a);
        b(2, 2 * a + 1) = q.gradients(0, a);
      }
      Eigen::Matrix3d c;
      c << lambda + 2 * mu, lambda, 0, lambda, lambda + 2 * mu, 0, 0, 0, mu;
      ke += q.weight * stiffening * b.transpose() * c * b;
    }
    for (Eigen::Index a = 0; a < 2 * n; ++a) {
      const int row = 2 * nodes[static_cast<size_t>(a / 2)] + static_cast<int>(a % 2);
      if (fixed[static_cast<size_t>(row)]) continue;
      for (Eigen::Index c = 0; c < 2 * n; ++c) {
        const int col = 2 * nodes[static_cast<size_t>(c / 2)] + static_cast<int>(c % 2);
        if (fixed[static_cast<size_t>(col)]) {
          rhs(row) -= ke(a, c) * increment(col);  // the prescribed motion's load on the free rows
        } else {
          triplets.emplace_back(row, col, ke(a, c));
        }
      }
    }
  }
  for (int i = 0; i < dofs; ++i) {
    if (fixed[static_cast<size_t>(i)]) triplets.emplace_back(i, i, 1.0), rhs(i) = increment(i);
  }
  Eigen::SparseMatrix<double> matrix(dofs, dofs);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  if (!solver_.factorize(matrix)) {
    report.reason = "the mesh-update matrix could not be factorised: " + solver_.reason();
    return report;
  }
  return place_mesh(space, space.displacement() + solver_.solve(rhs));
}

MeshMoveReport place_mesh(FluidSpace& space, const Eigen::VectorXd& displacement) {
  MeshMoveReport report;
  const Eigen::VectorXd before = space.displacement();
  space.set_displacement(displacement);
  report.min_relative_jacobian = space.min_relative_jacobian();
  if (!(report.min_relative_jacobian > 0.0)) {
    space.set_displacement(before);
    report.reason = "the moved fluid mesh would fold (min relative det J = " + std::to_string(report.min_relative_jacobian) + ")";
    return report;
  }
  report.ok = true;
  return report;
}

}  // namespace mufric::fluid
