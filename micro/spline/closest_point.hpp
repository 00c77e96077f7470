#pragma once
// Closest-point projection of a point onto a planar spline curve, robust on rough profiles of any
// degree: global seeding over every span, then per candidate a safeguarded Newton iteration on
// f(u) = C'(u)·(C(u) − x) inside a sign-change bracket (Press et al., Numerical Recipes 3rd ed.,
// §9.4 "rtsafe"), with a Levenberg–Marquardt step (Marquardt 1963) where the Newton model is not
// convex and bisection where both would leave the bracket.
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "micro/spline/spline_curve.hpp"

namespace mufric::spline {

// Stop when |f| ≤ this × |C'| × (|C − x| + curve scale) or the bracket is this narrow (× span).
inline constexpr double kProjectionRelativeTolerance = 1e-13;
inline constexpr int kProjectionMaxIterations = 100;

// C(u) at the seeding samples of every span of one period, for a curve that is searched very often
// (the rigid tool: every contact evaluation projects hundreds of points on it). It refers to the
// curve it was built from (which must outlive it); passed with another curve or another sampling
// density it is ignored.
class ProjectionSeeds {
 public:
  explicit ProjectionSeeds(const SplineCurve& curve, int samples_per_span = 0);
  const SplineCurve* curve() const { return curve_; }
  int samples_per_span() const { return per_span_; }
  const std::vector<double>& breaks() const { return breaks_; }
  const Eigen::Vector2d& point(int span, int sample) const { return points_[static_cast<size_t>(span * per_span_ + sample)]; }

 private:
  const SplineCurve* curve_;
  int per_span_;
  std::vector<double> breaks_;
  std::vector<Eigen::Vector2d> points_;
};

struct ProjectionOptions {
  // Samples per span for the global seeding; more catches narrower features between samples.
  int samples_per_span = 0;  // 0: 2p + 4
  // Periodic curves with a shift (profiles): the parameter range searched, in periods, centred on
  // the period of the point's own x (for closed curves one period is everything).
  int periods = 3;
  // When set (lo < hi), only the spans that meet [window_lo, window_hi] are searched: the caller
  // knows the closest point lies there (e.g. a contact search that bounds the distance). For
  // periodic curves the window may extend beyond one period.
  double window_lo = 0.0, window_hi = 0.0;
  // Precomputed seeding samples of this curve (not owned; null: evaluate the curve).
  const ProjectionSeeds* seeds = nullptr;
};

struct Projection {
  double u = 0.0;                  // parameter of the foot (periodic: may lie outside [lo, hi))
  Eigen::Vector2d foot = Eigen::Vector2d::Zero();
  double distance = 0.0;
  int iterations = 0;              // local iterations of the winning candidate
  int candidates = 0;              // local minima of the seeding that were refined
  bool converged = false;          // false: the best sample is returned and `reason` says why
  std::string reason;
};

Projection project(const SplineCurve& curve, const Eigen::Vector2d& x, const ProjectionOptions& options = {});

}  // namespace mufric::spline
