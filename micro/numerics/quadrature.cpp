#include "micro/numerics/quadrature.hpp"

#include <algorithm>
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

std::vector<ElementPoint> element_gauss_points(const std::vector<double>& breaks_u, const std::vector<double>& breaks_v,
                                               int points_u, int points_v) {
  std::vector<double> gu, wu, gv, wv;
  gauss_legendre(points_u, gu, wu);
  gauss_legendre(points_v, gv, wv);
  const int elements_u = static_cast<int>(breaks_u.size()) - 1, elements_v = static_cast<int>(breaks_v.size()) - 1;
  std::vector<ElementPoint> points;
  points.reserve(static_cast<size_t>(std::max(elements_u * elements_v, 0)) * gu.size() * gv.size());
  for (int ev = 0; ev < elements_v; ++ev) {
    for (int eu = 0; eu < elements_u; ++eu) {
      const double u0 = breaks_u[static_cast<size_t>(eu)], u1 = breaks_u[static_cast<size_t>(eu) + 1];
      const double v0 = breaks_v[static_cast<size_t>(ev)], v1 = breaks_v[static_cast<size_t>(ev) + 1];
      for (size_t b = 0; b < gv.size(); ++b) {
        for (size_t a = 0; a < gu.size(); ++a) {
          ElementPoint p;
          p.u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * gu[a];
          p.v = 0.5 * (v0 + v1) + 0.5 * (v1 - v0) * gv[b];
          p.weight = wu[a] * wv[b] * 0.25 * (u1 - u0) * (v1 - v0);
          p.span_u = u1 - u0;
          p.span_v = v1 - v0;
          p.element = eu + elements_u * ev;
          points.push_back(p);
        }
      }
    }
  }
  return points;
}

}  // namespace mufric::numerics
