#pragma once
// Planar tensor-product B-spline / NURBS patches (Piegl & Tiller 1997: A3.5/A3.6, rational A4.4),
// the geometry of an isogeometric solid. The first direction may be periodic with a shift per
// period (a chip interval that repeats along x); h- and p-refinement act on every row or column
// through the curve algorithms.
#include <vector>

#include <Eigen/Dense>

#include "micro/spline/spline_curve.hpp"

namespace mufric::spline {

// The rational basis functions that are non-zero at a parameter point, with their parametric
// derivatives, and the geometry there (periodic control points moved by their period's shift).
struct RationalBasis {
  std::vector<int> nodes;        // control-point index of each function (point of (i, j): i + nu·j)
  Eigen::VectorXd r, r_u, r_v;   // R_a and ∂R_a/∂u, ∂R_a/∂v
  Eigen::Vector2d x;             // S(u, v)
  Eigen::Matrix2d jacobian;      // columns ∂S/∂u, ∂S/∂v
};

class SplineSurface {
 public:
  // points(i + nu·j) is the control point of function i along u and j along v; weights likewise
  // (empty: B-spline). shift: translation per period of a periodic u basis.
  SplineSurface(SplineBasis u_basis, SplineBasis v_basis, Points2 points, Eigen::VectorXd weights = {},
                Eigen::Vector2d shift = Eigen::Vector2d::Zero());

  const SplineBasis& u_basis() const { return u_; }
  const SplineBasis& v_basis() const { return v_; }
  const Points2& points() const { return points_; }
  const Eigen::VectorXd& weights() const { return weights_; }
  bool is_rational() const { return weights_.size() > 0; }
  const Eigen::Vector2d& shift() const { return shift_; }
  int index(int i, int j) const { return i + u_.count() * j; }

  // Rational basis and geometry at (u, v) (A3.5 with the quotient rule of A4.4, first order).
  RationalBasis basis_at(double u, double v) const;
  Eigen::Vector2d point(double u, double v) const { return basis_at(u, v).x; }
  // Columns: ∂S/∂u, ∂S/∂v (the 2×2 Jacobian of the parameterisation).
  Eigen::Matrix2d jacobian(double u, double v) const { return basis_at(u, v).jacobian; }

  // The curve of row j (along u) or column i (along v).
  SplineCurve row(int j) const;
  SplineCurve column(int i) const;
  // The boundary curve at v = v_basis().hi() (the chip surface in the solid).
  SplineCurve top() const { return row(v_.count() - 1); }

  SplineSurface refined_u(const std::vector<double>& us) const;
  SplineSurface refined_v(const std::vector<double>& vs) const;
  // Splits every span of both directions into `parts_u` × `parts_v` equal spans.
  SplineSurface subdivided(int parts_u, int parts_v) const;
  SplineSurface elevated_u() const;
  SplineSurface elevated_v() const;

  // The patch between a bottom line y = y_bottom and a top curve (the chip surface), linear in v
  // and then elevated to `v_degree` with `v_spans` equal spans: points (x_i, y_bottom) → top_i.
  static SplineSurface extruded(const SplineCurve& top, double y_bottom, int v_degree, int v_spans);

 private:
  // The curve whose control points are points_(indices) (a row or a column of the net).
  SplineCurve curve_through(const SplineBasis& basis, const std::vector<int>& indices,
                            const Eigen::Vector2d& shift) const;
  // Builds a surface from curves along u (one per function of `across` = v) or along v (one per
  // function of `across` = u).
  static SplineSurface from_curves(const std::vector<SplineCurve>& curves, const SplineBasis& across,
                                   bool curves_along_u, const Eigen::Vector2d& shift);
  SplineBasis u_, v_;
  Points2 points_;
  Eigen::VectorXd weights_;
  Eigen::Vector2d shift_;
};

}  // namespace mufric::spline
