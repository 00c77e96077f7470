#pragma once
// The interface between the chip and the lubricant. The chip slides micrometres past the tool while
// the lubricant film is a fraction of a micrometre thick, so the fluid mesh cannot follow the chip's
// material points along the interface (it would shear by tens of film thicknesses): its columns stay
// at fixed x in the tool's frame and move only vertically (ALE), its bottom row is the interpolant of
// the chip's current spline surface at the column positions and its top row the tool's. The two
// exchange through the chip's own spline basis: the fluid's traction at a fluid boundary quadrature
// point goes to the chip's control points with the chip basis functions at the chip parameter under
// that point (the finite interpolation of Hosters et al., CMAME 332, 2018; partition of unity makes
// the total force the same on both sides to round-off), and the chip's velocity there is the
// fluid's wall velocity.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "micro/solid/solid_problem.hpp"
#include "micro/spline/spline_surface.hpp"

namespace mufric::coupling {

// A periodic curve seen from above as a graph over x: its parameter at a given x (x(t) advances by
// the period's shift per parameter period). Dense samples bracket the answer, bisection-secant
// (Illinois, Dowell & Jarratt, BIT 11, 1971) refines it to kGraphParameterTolerance. Where the curve
// folds back (a lip ploughed up by an asperity) several parameters share an x: the highest point is
// taken — the upper envelope, the surface the film above sees (what lies under a lip is left out).
inline constexpr double kGraphParameterTolerance = 1e-13;  // of the parameter period
class PeriodicGraph {
 public:
  // point(t): the curve at parameter t (any real t), [lo, lo + period) one period of parameters,
  // `samples` the bracketing samples per period.
  PeriodicGraph(std::function<Eigen::Vector2d(double)> point, double lo, double period, int samples);
  double parameter_at(double x) const;
  double height_at(double x) const { return point_(parameter_at(x)).y(); }
  double interval() const { return interval_; }  // the x shift per parameter period
  bool folded() const { return folded_; }        // x(t) turns back somewhere
  // The upper envelope with its cliffs ramped: max(height_at(x), max_k y_k − s |x − x_k|) over the
  // samples (x_k, y_k) and their periodic images, s = max_slope — the curve dilated from above by a cone
  // of that slope (a morphological dilation, e.g. Serra, Image Analysis and Mathematical Morphology,
  // 1982, ch. 2), sampled at the curve's own points. Where a lip folds over, height_at drops at the
  // lip's tip by the lip's height (what lies under it is left out); as the tip crosses an x, that x's
  // height jumps. The samples move with the curve, so their cones do not jump, and the ramp leaves
  // no drop steeper than s. A graph no steeper than s anywhere keeps its height.
  double ramped_height_at(double x, double max_slope) const;

 private:
  double root_in(size_t sample, double x) const;  // x(t) = x in [t_k, t_k+1], x within one period
  std::function<Eigen::Vector2d(double)> point_;
  double lo_, period_, interval_ = 0.0;
  bool folded_ = false;
  std::vector<double> t_, x_, y_;  // samples over one period in t, x_[0] the first
};

// The chip's top side (the patch's v = hi side) at a displacement and velocity.
class ChipSurface {
 public:
  explicit ChipSurface(const solid::IgaSpace& chip);
  ChipSurface(const ChipSurface&) = delete;  // its graph evaluates through `this`
  ChipSurface& operator=(const ChipSurface&) = delete;
  void update(const Eigen::VectorXd& u, const Eigen::VectorXd& v);
  double parameter_at(double x) const { return graph_.parameter_at(x); }
  const PeriodicGraph& graph() const { return graph_; }
  Eigen::Vector2d position(double t) const;  // current
  Eigen::Vector2d velocity(double t) const;
  // The nodal forces (2 per chip control point) of tractions t_q on the chip at current positions x_q
  // with line weights w_q: F_a = Σ_q N_a(ξ(x_q)) t_q w_q.
  Eigen::VectorXd nodal_forces(const std::vector<Eigen::Vector2d>& positions, const std::vector<Eigen::Vector2d>& tractions,
                               const std::vector<double>& weights) const;
  const solid::IgaSpace& space() const { return chip_; }

 private:
  const solid::IgaSpace& chip_;
  Eigen::VectorXd u_, v_;
  PeriodicGraph graph_;
};

// A load on the chip given as nodal forces (N per unit depth on each control point, 2 per point),
// held fixed through one structural solve: the fluid's traction of one coupling iteration.
class NodalLoad final : public solid::BoundaryInteraction {
 public:
  explicit NodalLoad(int dofs) : forces_(Eigen::VectorXd::Zero(dofs)) {}
  void set(const Eigen::VectorXd& forces);
  const Eigen::VectorXd& forces() const { return forces_; }
  std::vector<std::vector<int>> coupled_nodes() const override { return {}; }
  bool add(const Eigen::VectorXd& u, Eigen::VectorXd& force, solid::TangentAccumulator* tangent,
           std::string& reason) const override;

 private:
  Eigen::VectorXd forces_;
};

// The film's floor is the chip's surface ramped at this slope (PeriodicGraph::ramped_height_at): the
// chip's flanks gentler than 45° keep their height, and a lip's tip, whose cliff jumped a column's
// height by the lip's height as it crossed the column (a volume the incompressible film had to move
// within any step, however short: the default lubricated scene's stops at 800 and 1300 MPa), now
// raises a column over a slide of the lip's height.
inline constexpr double kFilmFloorMaxSlope = 1.0;

struct GapMeshOptions {
  int degree = 2;
  int elements_x = 64;   // columns along the interval
  int elements_y = 4;    // across the film
  // Where chip and tool come closer than this the film keeps this thickness: a closed pocket stays
  // connected to its neighbours through a film this thin, whose hydraulic resistance (∝ h⁻³) makes
  // it practically sealed, and the fluid solve never meets a zero-thickness element.
  double min_film = 5e-9;  // m
};

// The lubricant's patch over one interval [x0, x0 + L) between the chip surface (bottom, v = lo)
// and the tool (top), columns at the Greville abscissae of a periodic uniform basis in x; the
// bottom and top rows interpolate the chip's ramped heights (kFilmFloorMaxSlope) and the tool's
// there (the top lifted to the chip + min_film where they come closer), the rows between are spaced
// linearly.
spline::SplineSurface gap_patch(const PeriodicGraph& chip, const PeriodicGraph& tool, double x0, const GapMeshOptions& options);

// The bottom and top rows of such a patch for new chip and tool heights (same columns): the
// boundary positions the fluid mesh moves to.
Eigen::MatrixX2d gap_boundary_rows(const spline::SplineSurface& patch, const PeriodicGraph& chip, const PeriodicGraph& tool,
                                   const GapMeshOptions& options);

// The whole control net of such a patch (row i + nu j) for given bottom and top rows: each column's
// points spaced across the film at the v basis' Greville fractions, as the patch was built. This
// algebraic net cannot fold while every top point is above its bottom one (x grows along a row and
// y along a column, so det J = x_u y_v > 0), which gap_boundary_rows guarantees by min_film.
Eigen::MatrixX2d gap_net(const spline::SplineSurface& patch, const Eigen::MatrixX2d& rows);

}  // namespace mufric::coupling
