#pragma once
// The fluid's discretisation: one B-spline patch whose control net moves (arbitrary Lagrangian–
// Eulerian). Velocity and pressure use the patch's own basis (equal order, the isogeometric
// incompressible flow of Bazilevs et al., CMAME 197, 2007); the geometry is the reference net plus
// a mesh displacement in the same space, so a boundary row of the net can be the chip's surface
// spline itself. The parametric data (basis values and first and second parametric derivatives at
// the Gauss points) is computed once; every physical quantity is mapped through the current net
// (Hessians by the chain rule with the geometry's second derivatives).
#include <functional>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "micro/numerics/patch_side.hpp"
#include "micro/numerics/quadrature.hpp"
#include "micro/spline/spline_surface.hpp"

namespace mufric::fluid {

using numerics::Side;

// The non-zero basis functions at a parameter point and their parametric derivatives (rows of
// `derivatives`: N, N_u, N_v, N_uu, N_uv, N_vv).
struct ParametricPoint {
  std::vector<int> nodes;    // control-point index of each function
  std::vector<int> periods;  // periods of the shift to add to the function's control point
  Eigen::Matrix<double, 6, Eigen::Dynamic> derivatives;
  double u = 0.0, v = 0.0;
  double weight = 0.0;       // Gauss weight × parametric area (interior) or length (boundary)
  Eigen::Vector2d element_scale = Eigen::Vector2d::Ones();  // 2/Δu, 2/Δv: element coordinates per parameter
};

// The same point in the current configuration.
struct PhysicalPoint {
  Eigen::VectorXd values;         // N_a
  Eigen::Matrix2Xd gradients;     // ∂N_a/∂x
  Eigen::Matrix3Xd hessians;      // ∂²N_a/∂x², ∂²N_a/∂x∂y, ∂²N_a/∂y²
  Eigen::Vector2d position;
  Eigen::Matrix2d jacobian;       // ∂x/∂(u, v)
  Eigen::Matrix2d metric;         // G = (∂ξ/∂x)ᵀ(∂ξ/∂x), ξ the element coordinates in [−1, 1]²
  double weight = 0.0;            // quadrature weight × |det J| (interior) or × |∂x/∂t| (boundary)
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();  // boundary points: outward unit normal
};

// A moving-mesh spline space on one patch (non-rational; the first direction may be periodic).
class FluidSpace {
 public:
  explicit FluidSpace(spline::SplineSurface patch);

  const spline::SplineSurface& patch() const { return patch_; }
  int node_count() const { return static_cast<int>(patch_.points().rows()); }
  int elements_u() const { return elements_u_; }
  int elements_v() const { return elements_v_; }
  int element_count() const { return elements_u_ * elements_v_; }
  // The control points of element e (the same for all its Gauss points) and its Gauss points.
  const std::vector<int>& element_nodes(int e) const { return element_nodes_[static_cast<size_t>(e)]; }
  const std::vector<ParametricPoint>& element_points(int e) const { return element_points_[static_cast<size_t>(e)]; }
  // Gauss points along a side (degree + 1 per span), as parametric points of the patch.
  const std::vector<ParametricPoint>& side_points(Side side) const;
  bool has_side(Side side) const;
  std::vector<int> side_nodes(Side side) const;

  // Any parameter point (a periodic u is reduced into the period).
  ParametricPoint at(double u, double v) const;

  // The current control net: reference points plus a mesh displacement (2 per node).
  void set_displacement(const Eigen::VectorXd& displacement);
  const Eigen::VectorXd& displacement() const { return displacement_; }
  Eigen::Vector2d node_position(int node) const;  // current, unshifted
  // The point in the current configuration. boundary: the side the point lies on (sets weight from
  // the line element and the outward normal) or nullptr for an interior point.
  PhysicalPoint map(const ParametricPoint& p, const Side* boundary = nullptr) const;
  // Interpolates a nodal field with `components` values per node (stride `stride`, offset `offset`).
  static Eigen::Vector2d interpolate2(const ParametricPoint& p, const Eigen::VectorXd& field, int stride, int offset);
  static double interpolate1(const ParametricPoint& p, const Eigen::VectorXd& field, int stride, int offset);

  // ∫ dΩ over the current configuration.
  double area() const;
  // The smallest det ∂x/∂(u, v) at the Gauss points, relative to its reference value (1: undeformed;
  // ≤ 0: the mesh has folded).
  double min_relative_jacobian() const;

  // Control-point values whose trace on `side` interpolates g(x, t) (x current position, t the
  // side's curve parameter) at the side's Greville abscissae (exact for g in the trace space).
  // Returns (node, value) per side control point.
  std::vector<std::pair<int, Eigen::Vector2d>> interpolate_on_side(
      Side side, const std::function<Eigen::Vector2d(const Eigen::Vector2d& x, double t)>& g) const;

 private:
  spline::SplineSurface patch_;
  int elements_u_ = 0, elements_v_ = 0;
  std::vector<std::vector<int>> element_nodes_;
  std::vector<std::vector<ParametricPoint>> element_points_;
  std::vector<std::vector<ParametricPoint>> side_points_;  // bottom, top, left, right
  std::vector<double> reference_det_;  // per element × point, flattened
  Eigen::VectorXd displacement_;
  ParametricPoint evaluate(double u, double v) const;
};

// The rectangle [lo, hi] as a degree-p patch of nx × ny uniform spans, periodic along x with period
// hi.x − lo.x if asked; control points at the (unreduced) Greville abscissae, so that by linear
// precision the parameterisation is the identity, x(u, v) = (u, v).
spline::SplineSurface rectangle_patch(int degree, int nx, int ny, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                                      bool periodic_x);

}  // namespace mufric::fluid
