#include "micro/solid/iga_space.hpp"

#include <cmath>

#include "common/error.hpp"

namespace mufric::solid {

IgaSpace::IgaSpace(spline::SplineSurface patch) : patch_(std::move(patch)) {
  const auto bu = patch_.u_basis().breakpoints(), bv = patch_.v_basis().breakpoints();
  elements_u_ = static_cast<int>(bu.size()) - 1;
  elements_v_ = static_cast<int>(bv.size()) - 1;
  for (const auto& p : numerics::element_gauss_points(bu, bv, patch_.u_basis().degree() + 1, patch_.v_basis().degree() + 1)) {
    const spline::RationalBasis basis = patch_.basis_at(p.u, p.v);
    const double det = basis.jacobian.determinant();
    if (!(det > 0.0)) {
      throw Error("IGA patch: the parameterisation is not orientation-preserving (det J = " + std::to_string(det) +
                  " at u = " + std::to_string(p.u) + ", v = " + std::to_string(p.v) + ")");
    }
    QuadraturePoint qp;
    qp.nodes = basis.nodes;
    qp.values = basis.r;
    Eigen::Matrix2Xd parametric(2, basis.r.size());
    parametric.row(0) = basis.r_u.transpose();
    parametric.row(1) = basis.r_v.transpose();
    qp.gradients = basis.jacobian.transpose().inverse() * parametric;
    qp.weight = p.weight * det;
    qp.position = basis.x;
    qp.element = p.element;
    points_.push_back(std::move(qp));
  }
}

std::vector<BoundaryPoint> IgaSpace::boundary(numerics::Side side, int points_per_span) const {
  const bool along_u = side == numerics::Side::bottom || side == numerics::Side::top;
  if (!along_u && patch_.u_basis().is_periodic()) {
    throw Error("IGA patch: a periodic patch has no left or right side");
  }
  const auto& along = along_u ? patch_.u_basis() : patch_.v_basis();
  const auto& across = along_u ? patch_.v_basis() : patch_.u_basis();
  const double fixed = (side == numerics::Side::bottom || side == numerics::Side::left) ? across.lo() : across.hi();
  const double outward = (side == numerics::Side::bottom || side == numerics::Side::left) ? -1.0 : 1.0;
  std::vector<double> g, w;
  numerics::gauss_legendre(points_per_span > 0 ? points_per_span : along.degree() + 1, g, w);
  const auto breaks = along.breakpoints();
  std::vector<BoundaryPoint> out;
  for (size_t e = 0; e + 1 < breaks.size(); ++e) {
    for (size_t k = 0; k < g.size(); ++k) {
      const double t = 0.5 * (breaks[e] + breaks[e + 1]) + 0.5 * (breaks[e + 1] - breaks[e]) * g[k];
      const spline::RationalBasis b = along_u ? patch_.basis_at(t, fixed) : patch_.basis_at(fixed, t);
      const Eigen::Vector2d tangent = b.jacobian.col(along_u ? 0 : 1);
      const Eigen::Vector2d inward_direction = b.jacobian.col(along_u ? 1 : 0);
      Eigen::Vector2d normal(tangent.y(), -tangent.x());
      normal.normalize();
      if (normal.dot(inward_direction) * outward < 0.0) normal = -normal;
      BoundaryPoint bp;
      bp.nodes = b.nodes;
      bp.values = b.r;
      bp.weight = w[k] * 0.5 * (breaks[e + 1] - breaks[e]) * tangent.norm();
      bp.position = b.x;
      bp.normal = normal;
      bp.parameter = t;
      out.push_back(std::move(bp));
    }
  }
  return out;
}

std::vector<int> IgaSpace::side_nodes(numerics::Side side) const {
  const int nu = patch_.u_basis().count(), nv = patch_.v_basis().count();
  std::vector<int> out;
  switch (side) {
    case numerics::Side::bottom: for (int i = 0; i < nu; ++i) out.push_back(patch_.index(i, 0)); break;
    case numerics::Side::top: for (int i = 0; i < nu; ++i) out.push_back(patch_.index(i, nv - 1)); break;
    case numerics::Side::left:
    case numerics::Side::right:
      if (patch_.u_basis().is_periodic()) throw Error("IGA patch: a periodic patch has no left or right side");
      for (int j = 0; j < nv; ++j) out.push_back(patch_.index(side == numerics::Side::left ? 0 : nu - 1, j));
      break;
  }
  return out;
}

Eigen::Matrix2d IgaSpace::gradient(const QuadraturePoint& q, const Eigen::VectorXd& u) {
  Eigen::Matrix2d h = Eigen::Matrix2d::Zero();
  for (size_t a = 0; a < q.nodes.size(); ++a) {
    const Eigen::Vector2d ua = u.segment<2>(2 * q.nodes[a]);
    h += ua * q.gradients.col(static_cast<Eigen::Index>(a)).transpose();
  }
  return h;
}

Eigen::Vector2d IgaSpace::displacement(const Eigen::VectorXd& u, double pu, double pv) const {
  const spline::RationalBasis b = patch_.basis_at(pu, pv);
  Eigen::Vector2d out = Eigen::Vector2d::Zero();
  for (size_t a = 0; a < b.nodes.size(); ++a) out += b.r(static_cast<Eigen::Index>(a)) * u.segment<2>(2 * b.nodes[a]);
  return out;
}

spline::SplineSurface chip_patch(const spline::SplineCurve& surface, const ChipMeshOptions& options) {
  if (!surface.basis().is_periodic()) throw Error("chip patch: the surface curve must be periodic (one interval)");
  if (options.degree < 1) throw Error("chip patch: degree must be at least 1");
  const int existing = static_cast<int>(surface.basis().breakpoints().size()) - 1;
  if (options.spans_x < existing || options.spans_y < 1) {
    throw Error("chip patch: spans_x must be at least the surface fit's " + std::to_string(existing) +
                " spans and spans_y at least 1");
  }
  const double top_min = surface.points().col(1).minCoeff();
  if (!(options.y_bottom < top_min)) throw Error("chip patch: y_bottom must lie below the surface");
  spline::SplineCurve top = surface;
  while (top.basis().degree() < options.degree) top = top.elevated();
  // Split the longest spans until there are spans_x of them (keeps the fit's own knots).
  while (static_cast<int>(top.basis().breakpoints().size()) - 1 < options.spans_x) {
    const auto b = top.basis().breakpoints();
    size_t longest = 0;
    for (size_t e = 1; e + 1 < b.size(); ++e) {
      if (b[e + 1] - b[e] > b[longest + 1] - b[longest]) longest = e;
    }
    top = top.with_knot(0.5 * (b[longest] + b[longest + 1]));
  }
  if (!(options.grading >= 1.0)) throw Error("chip patch: grading must be at least 1");
  std::vector<double> v_knots;
  for (int k = 1; k < options.spans_y; ++k) {
    v_knots.push_back(1.0 - std::pow(1.0 - static_cast<double>(k) / options.spans_y, options.grading));
  }
  return spline::SplineSurface::extruded(top, options.y_bottom, options.degree, 1).refined_v(v_knots);
}

}  // namespace mufric::solid
