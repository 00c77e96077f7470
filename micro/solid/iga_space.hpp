#pragma once
// The isogeometric discretisation of one patch (Hughes, Cottrell & Bazilevs, CMAME 194, 2005):
// the patch's own NURBS basis carries the displacement, elements are the non-empty knot spans,
// (p+1)×(q+1) Gauss points per element. A periodic u basis identifies the wrapped functions, so
// periodicity is built into the control-point (dof) numbering. Everything here is in the reference
// configuration and computed once.
#include <vector>

#include <Eigen/Dense>

#include "micro/numerics/patch_side.hpp"
#include "micro/numerics/quadrature.hpp"
#include "micro/spline/spline_surface.hpp"

namespace mufric::solid {

// One quadrature point of the domain: the functions that are non-zero there, their values and
// reference gradients ∂R/∂X, and the weight × |det J|.
struct QuadraturePoint {
  std::vector<int> nodes;   // control-point indices (0..nodes-1)
  Eigen::VectorXd values;   // R_a
  Eigen::Matrix2Xd gradients;  // column a: ∂R_a/∂X
  double weight = 0.0;
  Eigen::Vector2d position;  // X
  int element = 0;
};


// A quadrature point on a boundary side: values, the weight × line Jacobian, and the outward unit
// normal (reference configuration); `parameter` is the curve parameter along the side.
struct BoundaryPoint {
  std::vector<int> nodes;
  Eigen::VectorXd values;
  double weight = 0.0;
  Eigen::Vector2d position, normal;
  double parameter = 0.0;
};

class IgaSpace {
 public:
  explicit IgaSpace(spline::SplineSurface patch);

  const spline::SplineSurface& patch() const { return patch_; }
  int node_count() const { return patch_.u_basis().count() * patch_.v_basis().count(); }
  int dof_count() const { return 2 * node_count(); }
  int element_count() const { return elements_u_ * elements_v_; }
  const std::vector<QuadraturePoint>& quadrature() const { return points_; }
  // Gauss points along a side, `points_per_span` per span (0: degree + 1). Throws Error for left or
  // right of a periodic patch: it has none.
  std::vector<BoundaryPoint> boundary(numerics::Side side, int points_per_span = 0) const;
  // Control points on a side (for Dirichlet conditions).
  std::vector<int> side_nodes(numerics::Side side) const;
  // The nodes' reference control-point positions (for linear fields: affine covariance).
  Eigen::Vector2d node_position(int node) const { return patch_.points().row(node).transpose(); }

  // Displacement gradient and value at a quadrature point for the nodal displacements u (2 per node).
  static Eigen::Matrix2d gradient(const QuadraturePoint& q, const Eigen::VectorXd& u);
  // Displacement anywhere in the patch, at parameters (u, v).
  Eigen::Vector2d displacement(const Eigen::VectorXd& u, double pu, double pv) const;

 private:
  spline::SplineSurface patch_;
  int elements_u_ = 0, elements_v_ = 0;
  std::vector<QuadraturePoint> points_;
};

// The chip patch of one periodic interval from its configuration: the surface curve (periodic,
// shift (L, 0)) raised to `degree` along x (a surface fit of higher degree keeps its own: lowering
// it would change the geometry) and refined to `spans_x` spans, extruded down to y_bottom with
// `degree` and `spans_y` spans across the thickness.
struct ChipMeshOptions {
  int degree = 2;
  int spans_x = 32;   // spans along the interval (at least the surface fit's own spans)
  int spans_y = 8;    // spans across the thickness
  double y_bottom = -5e-6;  // m, the loaded bottom Γ_B
  // Spans across the thickness shrink toward the surface, where contact concentrates the
  // gradients: knots at v_k = 1 − (1 − k/spans_y)^grading (1: uniform).
  double grading = 1.0;
};
spline::SplineSurface chip_patch(const spline::SplineCurve& surface, const ChipMeshOptions& options);

}  // namespace mufric::solid
