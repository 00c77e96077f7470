#pragma once
// Planar B-spline and NURBS curves, open or periodic (Piegl & Tiller 1997: point and derivatives
// A3.1/A3.2, rational derivatives A4.2, knot insertion A5.1; degree elevation by exact collocation,
// see elevate_degree).
#include <vector>

#include <Eigen/Dense>

#include "micro/spline/spline_basis.hpp"

namespace mufric::spline {

using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2>;
// A curve's derivatives at a point, rows r = 0..n: fixed capacity (no allocation per evaluation).
using CurveDerivatives = Eigen::Matrix<double, Eigen::Dynamic, 2, 0, kMaxDegree + 1, 2>;

class SplineCurve {
 public:
  // points: one row per basis function. weights: empty for a B-spline, else positive, one per
  // point (NURBS). shift: for periodic bases, the translation of the curve per period (a profile of
  // period L: (L, 0); a closed curve: 0). Throws Error naming an inconsistent argument.
  SplineCurve(SplineBasis basis, Points2 points, Eigen::VectorXd weights = {},
              Eigen::Vector2d shift = Eigen::Vector2d::Zero());

  const SplineBasis& basis() const { return basis_; }
  const Points2& points() const { return points_; }
  const Eigen::VectorXd& weights() const { return weights_; }
  bool is_rational() const { return weights_.size() > 0; }
  const Eigen::Vector2d& shift() const { return shift_; }

  Eigen::Vector2d point(double u) const;
  // Rows r = 0..n: d^r C/du^r at u (A3.2; for NURBS A4.2). Periodic curves accept any u.
  CurveDerivatives derivatives(double u, int n) const;

  // Control point of extended index i of a periodic curve (the point of i mod n moved by the shift
  // times its period); for open curves simply point i.
  Eigen::Vector2d extended_point(int index, int period) const;
  double extended_weight(int index) const { return is_rational() ? weights_(index) : 1.0; }

  // h-refinement: the same curve with one more knot at u (Boehm's insertion, A5.1 with r = 1).
  SplineCurve with_knot(double u) const;
  // Inserts every knot of `us` in turn.
  SplineCurve refined(const std::vector<double>& us) const;
  // Splits every span into `parts` equal spans.
  SplineCurve subdivided(int parts) const;
  // p-refinement: the same curve at degree p + 1 (every knot's multiplicity + 1). The elevated
  // space contains the curve, so collocation at the new basis's Greville abscissae (nodes that
  // satisfy the Schoenberg–Whitney condition) reproduces it exactly; it is done in homogeneous
  // coordinates for NURBS. Equivalent to A5.9's Bézier decomposition, in 20 lines instead of 200.
  SplineCurve elevated() const;

 private:
  // Rows r = 0..n: d^r/du^r of the homogeneous curve (w·C, w) at u (A3.2 applied to the weighted
  // control points; A4.2 turns it into the curve's derivatives).
  using HomogeneousDerivatives = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxDegree + 1, 3>;
  HomogeneousDerivatives homogeneous_derivatives(double u, int n) const;

  SplineBasis basis_;
  Points2 points_;
  Eigen::VectorXd weights_;
  Eigen::Vector2d shift_;
};

}  // namespace mufric::spline
