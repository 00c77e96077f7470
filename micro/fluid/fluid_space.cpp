#include "micro/fluid/fluid_space.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "common/error.hpp"

namespace mufric::fluid {

namespace {

size_t side_slot(Side side) { return static_cast<size_t>(side); }

bool along_u(Side side) { return side == Side::bottom || side == Side::top; }

}  // namespace

FluidSpace::FluidSpace(spline::SplineSurface patch) : patch_(std::move(patch)) {
  if (patch_.is_rational()) throw Error("fluid space: the patch must be a (non-rational) B-spline patch");
  if (patch_.v_basis().is_periodic()) throw Error("fluid space: only the first direction may be periodic");
  displacement_ = Eigen::VectorXd::Zero(2 * node_count());
  const auto bu = patch_.u_basis().breakpoints(), bv = patch_.v_basis().breakpoints();
  elements_u_ = static_cast<int>(bu.size()) - 1;
  elements_v_ = static_cast<int>(bv.size()) - 1;
  element_points_.resize(static_cast<size_t>(elements_u_ * elements_v_));
  for (const auto& q : numerics::element_gauss_points(bu, bv, patch_.u_basis().degree() + 1, patch_.v_basis().degree() + 1)) {
    ParametricPoint p = evaluate(q.u, q.v);
    p.weight = q.weight;
    p.element_scale = Eigen::Vector2d(2.0 / q.span_u, 2.0 / q.span_v);
    element_points_[static_cast<size_t>(q.element)].push_back(std::move(p));
  }
  for (const auto& points : element_points_) element_nodes_.push_back(points.front().nodes);
  side_points_.resize(4);
  for (Side side : {Side::bottom, Side::top, Side::left, Side::right}) {
    if (!has_side(side)) continue;
    const auto& along = along_u(side) ? patch_.u_basis() : patch_.v_basis();
    const auto& across = along_u(side) ? patch_.v_basis() : patch_.u_basis();
    const double fixed = (side == Side::bottom || side == Side::left) ? across.lo() : across.hi();
    std::vector<double> g, w;
    numerics::gauss_legendre(along.degree() + 1, g, w);
    const auto breaks = along.breakpoints();
    for (size_t e = 0; e + 1 < breaks.size(); ++e) {
      for (size_t k = 0; k < g.size(); ++k) {
        const double t = 0.5 * (breaks[e] + breaks[e + 1]) + 0.5 * (breaks[e + 1] - breaks[e]) * g[k];
        ParametricPoint p = along_u(side) ? evaluate(t, fixed) : evaluate(fixed, t);
        p.weight = w[k] * 0.5 * (breaks[e + 1] - breaks[e]);
        side_points_[side_slot(side)].push_back(std::move(p));
      }
    }
  }
  for (int e = 0; e < element_count(); ++e) {
    for (const auto& p : element_points(e)) reference_det_.push_back(map(p).jacobian.determinant());
  }
  for (double det : reference_det_) {
    if (!(det > 0.0)) throw Error("fluid space: the patch's parameterisation is not orientation-preserving");
  }
}

bool FluidSpace::has_side(Side side) const { return along_u(side) || !patch_.u_basis().is_periodic(); }

const std::vector<ParametricPoint>& FluidSpace::side_points(Side side) const {
  if (!has_side(side)) throw Error("fluid space: a periodic patch has no left or right side");
  return side_points_[side_slot(side)];
}

std::vector<int> FluidSpace::side_nodes(Side side) const {
  const int nu = patch_.u_basis().count(), nv = patch_.v_basis().count();
  std::vector<int> out;
  if (!has_side(side)) throw Error("fluid space: a periodic patch has no left or right side");
  if (along_u(side)) {
    for (int i = 0; i < nu; ++i) out.push_back(patch_.index(i, side == Side::bottom ? 0 : nv - 1));
  } else {
    for (int j = 0; j < nv; ++j) out.push_back(patch_.index(side == Side::left ? 0 : nu - 1, j));
  }
  return out;
}

ParametricPoint FluidSpace::evaluate(double u, double v) const {
  const auto& bu = patch_.u_basis();
  const auto& bv = patch_.v_basis();
  const auto au = bu.locate(u), av = bv.locate(v);
  const spline::BasisDerivatives nu = bu.derivatives(au.span, au.u, 2), nv = bv.derivatives(av.span, av.u, 2);
  const int p = bu.degree(), q = bv.degree(), count = (p + 1) * (q + 1);
  ParametricPoint out;
  out.u = au.u, out.v = av.u;
  out.nodes.resize(static_cast<size_t>(count));
  out.periods.resize(static_cast<size_t>(count));
  out.derivatives.resize(6, count);
  for (int j = 0; j <= q; ++j) {
    for (int i = 0; i <= p; ++i) {
      const int a = i + (p + 1) * j;
      out.nodes[static_cast<size_t>(a)] = patch_.index(bu.function_index(au.span, i), bv.function_index(av.span, j));
      out.periods[static_cast<size_t>(a)] = bu.is_periodic() ? bu.function_period(au.span, i) : 0;
      out.derivatives.col(a) << nu(0, i) * nv(0, j), nu(1, i) * nv(0, j), nu(0, i) * nv(1, j), nu(2, i) * nv(0, j),
          nu(1, i) * nv(1, j), nu(0, i) * nv(2, j);
    }
  }
  return out;
}

ParametricPoint FluidSpace::at(double u, double v) const { return evaluate(u, v); }

void FluidSpace::set_displacement(const Eigen::VectorXd& displacement) {
  if (displacement.size() != 2 * node_count()) throw Error("fluid space: mesh displacement has the wrong size");
  displacement_ = displacement;
}

Eigen::Vector2d FluidSpace::node_position(int node) const {
  return patch_.points().row(node).transpose() + displacement_.segment<2>(2 * node);
}

PhysicalPoint FluidSpace::map(const ParametricPoint& p, const Side* boundary) const {
  const auto n = static_cast<Eigen::Index>(p.nodes.size());
  PhysicalPoint out;
  out.values = p.derivatives.row(0).transpose();
  out.position.setZero();
  out.jacobian.setZero();
  Eigen::Vector2d x_uu = Eigen::Vector2d::Zero(), x_uv = Eigen::Vector2d::Zero(), x_vv = Eigen::Vector2d::Zero();
  for (Eigen::Index a = 0; a < n; ++a) {
    const auto s = static_cast<size_t>(a);
    const Eigen::Vector2d xa = node_position(p.nodes[s]) + p.periods[s] * patch_.shift();
    out.position += p.derivatives(0, a) * xa;
    out.jacobian.col(0) += p.derivatives(1, a) * xa;
    out.jacobian.col(1) += p.derivatives(2, a) * xa;
    x_uu += p.derivatives(3, a) * xa;
    x_uv += p.derivatives(4, a) * xa;
    x_vv += p.derivatives(5, a) * xa;
  }
  const Eigen::Matrix2d inverse = out.jacobian.inverse();  // ∂(u, v)/∂x
  out.gradients = inverse.transpose() * p.derivatives.middleRows(1, 2);
  // ∂²N/∂ξ² = Jᵀ (∂²N/∂x²) J + Σ_i ∂N/∂x_i ∂²x_i/∂ξ²  ⇒  ∂²N/∂x² = J⁻ᵀ (∂²N/∂ξ² − Σ_i …) J⁻¹.
  out.hessians.resize(3, n);
  for (Eigen::Index a = 0; a < n; ++a) {
    const double gx = out.gradients(0, a), gy = out.gradients(1, a);
    Eigen::Matrix2d m;
    m(0, 0) = p.derivatives(3, a) - gx * x_uu.x() - gy * x_uu.y();
    m(0, 1) = m(1, 0) = p.derivatives(4, a) - gx * x_uv.x() - gy * x_uv.y();
    m(1, 1) = p.derivatives(5, a) - gx * x_vv.x() - gy * x_vv.y();
    const Eigen::Matrix2d h = inverse.transpose() * m * inverse;
    out.hessians.col(a) << h(0, 0), h(0, 1), h(1, 1);
  }
  const Eigen::Matrix2d dxi_dx = p.element_scale.asDiagonal() * inverse;
  out.metric = dxi_dx.transpose() * dxi_dx;
  if (boundary == nullptr) {
    out.weight = p.weight * std::abs(out.jacobian.determinant());
  } else {
    const Eigen::Vector2d tangent = out.jacobian.col(along_u(*boundary) ? 0 : 1);
    const Eigen::Vector2d inward = out.jacobian.col(along_u(*boundary) ? 1 : 0);
    const double outward = (*boundary == Side::bottom || *boundary == Side::left) ? -1.0 : 1.0;
    out.normal = Eigen::Vector2d(tangent.y(), -tangent.x()).normalized();
    if (out.normal.dot(inward) * outward < 0.0) out.normal = -out.normal;
    out.weight = p.weight * tangent.norm();
  }
  return out;
}

Eigen::Vector2d FluidSpace::interpolate2(const ParametricPoint& p, const Eigen::VectorXd& field, int stride, int offset) {
  Eigen::Vector2d out = Eigen::Vector2d::Zero();
  for (size_t a = 0; a < p.nodes.size(); ++a) {
    out += p.derivatives(0, static_cast<Eigen::Index>(a)) * field.segment<2>(stride * p.nodes[a] + offset);
  }
  return out;
}

double FluidSpace::interpolate1(const ParametricPoint& p, const Eigen::VectorXd& field, int stride, int offset) {
  double out = 0.0;
  for (size_t a = 0; a < p.nodes.size(); ++a) {
    out += p.derivatives(0, static_cast<Eigen::Index>(a)) * field(stride * p.nodes[a] + offset);
  }
  return out;
}

double FluidSpace::area() const {
  double out = 0.0;
  for (int e = 0; e < element_count(); ++e) {
    for (const auto& p : element_points(e)) out += map(p).weight;
  }
  return out;
}

double FluidSpace::min_relative_jacobian() const {
  double out = std::numeric_limits<double>::infinity();
  size_t k = 0;
  for (int e = 0; e < element_count(); ++e) {
    for (const auto& p : element_points(e)) out = std::min(out, map(p).jacobian.determinant() / reference_det_[k++]);
  }
  return out;
}

std::vector<std::pair<int, Eigen::Vector2d>> FluidSpace::interpolate_on_side(
    Side side, const std::function<Eigen::Vector2d(const Eigen::Vector2d& x, double t)>& g) const {
  const auto& along = along_u(side) ? patch_.u_basis() : patch_.v_basis();
  const auto& across = along_u(side) ? patch_.v_basis() : patch_.u_basis();
  const double fixed = (side == Side::bottom || side == Side::left) ? across.lo() : across.hi();
  const std::vector<int> nodes = side_nodes(side);
  const std::vector<double> abscissae = along.greville();
  const auto n = static_cast<Eigen::Index>(nodes.size());
  // Collocation: Σ_j N_j(t_k) c_j = g(x(t_k)) at the Greville abscissae t_k (Schoenberg–Whitney
  // holds, so the system is regular); the across-direction basis is 1 on the side.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd rhs(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = abscissae[static_cast<size_t>(k)];
    const auto loc = along.locate(t);
    const Eigen::VectorXd values = along.values(loc.span, loc.u);
    for (int j = 0; j <= along.degree(); ++j) a(k, along.function_index(loc.span, j)) += values(j);
    const ParametricPoint p = along_u(side) ? evaluate(t, fixed) : evaluate(fixed, t);
    rhs.row(k) = g(map(p).position, t).transpose();
  }
  const Eigen::MatrixXd c = a.fullPivLu().solve(rhs);
  std::vector<std::pair<int, Eigen::Vector2d>> out;
  for (Eigen::Index k = 0; k < n; ++k) out.emplace_back(nodes[static_cast<size_t>(k)], c.row(k).transpose());
  return out;
}

spline::SplineSurface rectangle_patch(int degree, int nx, int ny, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                                      bool periodic_x) {
  if (degree < 1 || nx < 1 || ny < 1 || !(hi.x() > lo.x()) || !(hi.y() > lo.y())) {
    throw Error("rectangle patch: needs degree >= 1, at least one span each way and hi > lo");
  }
  const spline::SplineBasis bu = periodic_x ? spline::SplineBasis::periodic_uniform(degree, nx, lo.x(), hi.x())
                                            : spline::SplineBasis::open_uniform(degree, nx, lo.x(), hi.x());
  const spline::SplineBasis bv = spline::SplineBasis::open_uniform(degree, ny, lo.y(), hi.y());
  spline::Points2 points(bu.count() * bv.count(), 2);
  for (int j = 0; j < bv.count(); ++j) {
    for (int i = 0; i < bu.count(); ++i) {
      points.row(i + bu.count() * j) = Eigen::RowVector2d(bu.greville_abscissa(i), bv.greville_abscissa(j));
    }
  }
  const Eigen::Vector2d shift = periodic_x ? Eigen::Vector2d(hi.x() - lo.x(), 0.0) : Eigen::Vector2d::Zero();
  return spline::SplineSurface(bu, bv, std::move(points), {}, shift);
}

}  // namespace mufric::fluid
