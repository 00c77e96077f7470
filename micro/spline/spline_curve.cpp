#include "micro/spline/spline_curve.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"

namespace mufric::spline {
namespace {

double binomial(int n, int k) {
  double b = 1.0;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

}  // namespace

SplineCurve::SplineCurve(SplineBasis basis, Points2 points, Eigen::VectorXd weights, Eigen::Vector2d shift)
    : basis_(std::move(basis)), points_(std::move(points)), weights_(std::move(weights)), shift_(shift) {
  if (points_.rows() != basis_.count()) {
    throw Error("spline curve: " + std::to_string(points_.rows()) + " control points for " +
                std::to_string(basis_.count()) + " basis functions");
  }
  if (!points_.allFinite()) throw Error("spline curve: a control point is not finite");
  if (weights_.size() != 0) {
    if (weights_.size() != points_.rows()) throw Error("spline curve: one weight per control point is needed");
    if (!(weights_.array() > 0.0).all() || !weights_.allFinite()) throw Error("spline curve: weights must be positive");
  }
  if (!basis_.is_periodic() && !shift_.isZero()) throw Error("spline curve: a shift needs a periodic basis");
}

Eigen::Vector2d SplineCurve::extended_point(int index, int period) const {
  return points_.row(index).transpose() + period * shift_;
}

SplineCurve::HomogeneousDerivatives SplineCurve::homogeneous_derivatives(double u, int n) const {
  const auto at = basis_.locate(u);
  const BasisDerivatives ders = basis_.derivatives(at.span, at.u, n);
  HomogeneousDerivatives h = HomogeneousDerivatives::Zero(n + 1, 3);
  for (int j = 0; j <= basis_.degree(); ++j) {
    const int i = basis_.function_index(at.span, j);
    const double weight = extended_weight(i);
    Eigen::RowVector3d weighted;
    weighted << weight * extended_point(i, basis_.function_period(at.span, j) + at.periods).transpose(), weight;
    for (int r = 0; r <= n; ++r) h.row(r) += ders(r, j) * weighted;
  }
  return h;
}

CurveDerivatives SplineCurve::derivatives(double u, int n) const {
  const auto h = homogeneous_derivatives(u, n);
  // A4.2: C^(k) = (A^(k) − Σ_{i=1..k} C(k,i) w^(i) C^(k−i)) / w.
  CurveDerivatives c(n + 1, 2);
  for (int k = 0; k <= n; ++k) {
    Eigen::RowVector2d v = h.row(k).head<2>();
    for (int i = 1; i <= k; ++i) v -= binomial(k, i) * h(i, 2) * c.row(k - i);
    c.row(k) = v / h(0, 2);
  }
  return c;
}

Eigen::Vector2d SplineCurve::point(double u) const { return derivatives(u, 0).row(0).transpose(); }

SplineCurve SplineCurve::with_knot(double u) const {
  const SplineBasis refined_basis = basis_.with_knot(u);
  const auto at = basis_.locate(u);
  const int k = at.span, p = basis_.degree(), n = basis_.count();
  const double ur = at.u;
  // Homogeneous control point of extended index i (periodic indices wrap with their shift).
  auto homogeneous = [&](int i) {
    int index = i, period = 0;
    if (basis_.is_periodic()) {
      period = i >= 0 ? i / n : -((-i + n - 1) / n);
      index = i - period * n;
    }
    const double w = extended_weight(index);
    Eigen::Vector3d h;
    h << w * extended_point(index, period), w;
    return h;
  };
  auto blend = [&](int i) {
    const double alpha = (ur - basis_.knot(i)) / (basis_.knot(i + p) - basis_.knot(i));
    return Eigen::Vector3d(alpha * homogeneous(i) + (1.0 - alpha) * homogeneous(i - 1));
  };
  auto in_window = [&](int i) { return i >= k - p + 1 && i <= k; };
  const int m = n + 1;
  Points2 points(m, 2);
  Eigen::VectorXd weights(m);
  for (int j = 0; j < m; ++j) {
    Eigen::Vector3d h;
    Eigen::Vector2d moved = Eigen::Vector2d::Zero();
    if (in_window(j)) {
      h = blend(j);
    } else if (basis_.is_periodic() && in_window(j - m)) {
      h = blend(j - m);  // the image of the insertion one period later
      moved = shift_;
    } else if (j <= k - p) {
      h = homogeneous(j);
    } else {
      h = homogeneous(j - 1);
    }
    weights(j) = h(2);
    points.row(j) = (h.head<2>() / h(2) + moved).transpose();
  }
  return SplineCurve(refined_basis, std::move(points), is_rational() ? weights : Eigen::VectorXd(), shift_);
}

SplineCurve SplineCurve::refined(const std::vector<double>& us) const {
  SplineCurve c = *this;
  for (const double u : us) c = c.with_knot(u);
  return c;
}

SplineCurve SplineCurve::subdivided(int parts) const {
  std::vector<double> inserts;
  const auto breaks = basis_.breakpoints();
  for (size_t e = 0; e + 1 < breaks.size(); ++e) {
    for (int q = 1; q < parts; ++q) inserts.push_back(breaks[e] + (breaks[e + 1] - breaks[e]) * q / parts);
  }
  return refined(inserts);
}

SplineCurve SplineCurve::elevated() const {
  const SplineBasis high = basis_.elevated();
  const int m = high.count();
  const std::vector<double> nodes = high.greville();
  // Collocation: Σ_i N'_i(g) Qw_i = Cw(g), with Qw_i = (w_i (Q_i + period_i S), w_i).
  Eigen::MatrixXd collocation = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd shift_count = Eigen::MatrixXd::Zero(m, m);  // Σ N'_i period_i per row, split by column
  Eigen::MatrixXd rhs(m, 3);
  for (int r = 0; r < m; ++r) {
    const double g = nodes[static_cast<size_t>(r)];
    const auto at = high.locate(g);
    const Eigen::VectorXd n = high.values(at.span, at.u);
    for (int j = 0; j <= high.degree(); ++j) {
      const int i = high.function_index(at.span, j);
      collocation(r, i) += n(j);
      shift_count(r, i) += n(j) * (high.function_period(at.span, j) + at.periods);
    }
    // The homogeneous curve at g, in the same period as the collocation row.
    rhs.row(r) = homogeneous_derivatives(g, 0).row(0);
  }
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(collocation);
  const Eigen::VectorXd weights = lu.solve(rhs.col(2));
  // w_i Q_i: subtract the known shift terms Σ N'_i w_i period_i S.
  Eigen::MatrixXd shifted = rhs.leftCols(2) - (shift_count * weights) * shift_.transpose();
  const Eigen::MatrixXd weighted = lu.solve(shifted);
  Points2 points(m, 2);
  for (int i = 0; i < m; ++i) points.row(i) = weighted.row(i) / weights(i);
  return SplineCurve(high, std::move(points), is_rational() ? weights : Eigen::VectorXd(), shift_);
}

}  // namespace mufric::spline
