#include "micro/spline/spline_surface.hpp"

#include <string>

#include "common/error.hpp"

namespace mufric::spline {

SplineSurface::SplineSurface(SplineBasis u_basis, SplineBasis v_basis, Points2 points, Eigen::VectorXd weights,
                             Eigen::Vector2d shift)
    : u_(std::move(u_basis)), v_(std::move(v_basis)), points_(std::move(points)), weights_(std::move(weights)),
      shift_(shift) {
  if (points_.rows() != u_.count() * v_.count()) {
    throw Error("spline surface: " + std::to_string(points_.rows()) + " control points for " +
                std::to_string(u_.count()) + " × " + std::to_string(v_.count()) + " functions");
  }
  if (v_.is_periodic()) throw Error("spline surface: only the u direction may be periodic");
  if (weights_.size() != 0 && weights_.size() != points_.rows()) {
    throw Error("spline surface: one weight per control point is needed");
  }
  if (weights_.size() != 0 && !(weights_.array() > 0.0).all()) throw Error("spline surface: weights must be positive");
  if (!u_.is_periodic() && !shift_.isZero()) throw Error("spline surface: a shift needs a periodic u basis");
}

RationalBasis SplineSurface::basis_at(double u, double v) const {
  const auto au = u_.locate(u), av = v_.locate(v);
  const BasisDerivatives nu = u_.derivatives(au.span, au.u, 1), nv = v_.derivatives(av.span, av.u, 1);
  const int p = u_.degree(), q = v_.degree(), count = (p + 1) * (q + 1);
  RationalBasis b;
  b.nodes.resize(static_cast<size_t>(count));
  b.r.resize(count), b.r_u.resize(count), b.r_v.resize(count);
  double w = 0.0, w_u = 0.0, w_v = 0.0;
  std::vector<Eigen::Vector2d> positions(static_cast<size_t>(count));
  for (int j = 0; j <= q; ++j) {
    for (int i = 0; i <= p; ++i) {
      const int a = i + (p + 1) * j;
      const int node = index(u_.function_index(au.span, i), v_.function_index(av.span, j));
      const double weight = is_rational() ? weights_(node) : 1.0;
      b.nodes[static_cast<size_t>(a)] = node;
      b.r(a) = nu(0, i) * nv(0, j) * weight;
      b.r_u(a) = nu(1, i) * nv(0, j) * weight;
      b.r_v(a) = nu(0, i) * nv(1, j) * weight;
      w += b.r(a), w_u += b.r_u(a), w_v += b.r_v(a);
      positions[static_cast<size_t>(a)] =
          points_.row(node).transpose() + (u_.function_period(au.span, i) + au.periods) * shift_;
    }
  }
  // Quotient rule: R = N w / W, R_u = (N_u w − R W_u) / W.
  b.r /= w;
  b.r_u = (b.r_u - b.r * w_u) / w;
  b.r_v = (b.r_v - b.r * w_v) / w;
  b.x.setZero();
  b.jacobian.setZero();
  for (int a = 0; a < count; ++a) {
    b.x += b.r(a) * positions[static_cast<size_t>(a)];
    b.jacobian.col(0) += b.r_u(a) * positions[static_cast<size_t>(a)];
    b.jacobian.col(1) += b.r_v(a) * positions[static_cast<size_t>(a)];
  }
  return b;
}

SplineCurve SplineSurface::curve_through(const SplineBasis& basis, const std::vector<int>& indices,
                                         const Eigen::Vector2d& shift) const {
  const auto n = static_cast<Eigen::Index>(indices.size());
  Points2 p(n, 2);
  Eigen::VectorXd w(is_rational() ? n : 0);
  for (Eigen::Index k = 0; k < n; ++k) {
    p.row(k) = points_.row(indices[static_cast<size_t>(k)]);
    if (is_rational()) w(k) = weights_(indices[static_cast<size_t>(k)]);
  }
  return SplineCurve(basis, std::move(p), std::move(w), shift);
}

SplineCurve SplineSurface::row(int j) const {
  std::vector<int> indices;
  for (int i = 0; i < u_.count(); ++i) indices.push_back(index(i, j));
  return curve_through(u_, indices, shift_);
}

SplineCurve SplineSurface::column(int i) const {
  std::vector<int> indices;
  for (int j = 0; j < v_.count(); ++j) indices.push_back(index(i, j));
  return curve_through(v_, indices, Eigen::Vector2d::Zero());
}

SplineSurface SplineSurface::from_curves(const std::vector<SplineCurve>& curves, const SplineBasis& across,
                                         bool curves_along_u, const Eigen::Vector2d& shift) {
  const SplineBasis& along = curves.front().basis();
  const SplineBasis& u = curves_along_u ? along : across;
  const SplineBasis& v = curves_along_u ? across : along;
  const bool rational = curves.front().is_rational();
  Points2 p(u.count() * v.count(), 2);
  Eigen::VectorXd w(rational ? p.rows() : 0);
  for (int c = 0; c < across.count(); ++c) {
    for (int k = 0; k < along.count(); ++k) {
      const int i = curves_along_u ? k : c, j = curves_along_u ? c : k;
      p.row(i + u.count() * j) = curves[static_cast<size_t>(c)].points().row(k);
      if (rational) w(i + u.count() * j) = curves[static_cast<size_t>(c)].weights()(k);
    }
  }
  return SplineSurface(u, v, std::move(p), std::move(w), shift);
}

SplineSurface SplineSurface::refined_u(const std::vector<double>& us) const {
  std::vector<SplineCurve> rows;
  for (int j = 0; j < v_.count(); ++j) rows.push_back(row(j).refined(us));
  return from_curves(rows, v_, true, rows.front().shift());
}

SplineSurface SplineSurface::refined_v(const std::vector<double>& vs) const {
  std::vector<SplineCurve> columns;
  for (int i = 0; i < u_.count(); ++i) columns.push_back(column(i).refined(vs));
  return from_curves(columns, u_, false, shift_);
}

SplineSurface SplineSurface::elevated_u() const {
  std::vector<SplineCurve> rows;
  for (int j = 0; j < v_.count(); ++j) rows.push_back(row(j).elevated());
  return from_curves(rows, v_, true, rows.front().shift());
}

SplineSurface SplineSurface::elevated_v() const {
  std::vector<SplineCurve> columns;
  for (int i = 0; i < u_.count(); ++i) columns.push_back(column(i).elevated());
  return from_curves(columns, u_, false, shift_);
}

namespace {
std::vector<double> interior_splits(const SplineBasis& basis, int parts) {
  std::vector<double> out;
  const auto breaks = basis.breakpoints();
  for (size_t e = 0; e + 1 < breaks.size(); ++e) {
    for (int q = 1; q < parts; ++q) out.push_back(breaks[e] + (breaks[e + 1] - breaks[e]) * q / parts);
  }
  return out;
}
}  // namespace

SplineSurface SplineSurface::subdivided(int parts_u, int parts_v) const {
  return refined_u(interior_splits(u_, parts_u)).refined_v(interior_splits(v_, parts_v));
}

SplineSurface SplineSurface::extruded(const SplineCurve& top, double y_bottom, int v_degree, int v_spans) {
  const SplineBasis linear = SplineBasis::open_uniform(1, 1, 0.0, 1.0);
  const int nu = top.basis().count();
  Points2 p(2 * nu, 2);
  Eigen::VectorXd w(top.is_rational() ? 2 * nu : 0);
  for (int i = 0; i < nu; ++i) {
    p.row(i) = Eigen::RowVector2d(top.points()(i, 0), y_bottom);
    p.row(i + nu) = top.points().row(i);
    if (top.is_rational()) w(i) = w(i + nu) = top.weights()(i);
  }
  SplineSurface s(top.basis(), linear, std::move(p), std::move(w), top.shift());
  for (int d = 1; d < v_degree; ++d) s = s.elevated_v();
  return s.subdivided(1, v_spans);
}

}  // namespace mufric::spline
