#include "micro/spline/closest_point.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mufric::spline {
namespace {

struct Sample {
  double u;
  double distance_squared;
  Eigen::Vector2d point;  // C(u), kept for the length scale
};

struct LocalResult {
  double u;
  double distance_squared;
  int iterations;
  bool converged;
};

// f(u) = C'·(C − x) and f'(u) = C''·(C − x) + |C'|²: the derivative of ½|C − x|² and its slope.
struct Stationarity {
  double f, slope, distance_squared, speed;
};

Stationarity stationarity(const SplineCurve& curve, const Eigen::Vector2d& x, double u) {
  const CurveDerivatives d = curve.derivatives(u, 2);
  const Eigen::Vector2d r = d.row(0).transpose() - x;
  const Eigen::Vector2d c1 = d.row(1).transpose(), c2 = d.row(2).transpose();
  return {c1.dot(r), c2.dot(r) + c1.squaredNorm(), r.squaredNorm(), c1.norm()};
}

// f = C′·(C − x) is known only to the rounding of C − x, about eps (|C| + |x|) ≤ eps (2|x| + |C − x|)
// per coordinate, times |C′|: no iteration gets |f| below that. The relative tolerance alone, 1e-13 of
// |C′| (d + length scale), asked for less than that once the coordinates are ~20 µm from the origin
// and the point sits on the curve (d ≈ 0, a short length scale): a 20 µm cell's periodic seam never
// converged there (bench/studies/served_interval/README.md, "The cell width as a lever"). 8 ulps leaves room for the sums in C.
constexpr double kStationarityRoundingUlps = 8.0;

double stationarity_tolerance(const Stationarity& s, const Eigen::Vector2d& x, double length_scale) {
  const double distance = std::sqrt(s.distance_squared);
  const double rounding = kStationarityRoundingUlps * std::numeric_limits<double>::epsilon() *
                          (2.0 * x.lpNorm<Eigen::Infinity>() + distance);
  return s.speed * std::max(kProjectionRelativeTolerance * (distance + length_scale), rounding);
}

// Golden-section search for the minimum of |C(u) − x|² on [a, b] (Numerical Recipes §10.2): the
// last resort when the derivative-based iteration lands on a stationary point that is no minimum.
LocalResult golden_section(const SplineCurve& curve, const Eigen::Vector2d& x, double a, double b) {
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  const double tolerance = kProjectionRelativeTolerance * (b - a);
  auto distance2 = [&](double u) { return (curve.point(u) - x).squaredNorm(); };
  double c = b - ratio * (b - a), d = a + ratio * (b - a);
  double fc = distance2(c), fd = distance2(d);
  int it = 0;
  while (b - a > tolerance && it < 200) {
    ++it;
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - ratio * (b - a), fc = distance2(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + ratio * (b - a), fd = distance2(d);
    }
  }
  const double u = fc < fd ? c : d;
  return {u, std::min(fc, fd), it, true};
}

// Minimises ½|C(u) − x|² on [a, b], where a sampled local minimum `seed` lies between a and b.
LocalResult refine(const SplineCurve& curve, const Eigen::Vector2d& x, double a, double b, double seed,
                   double length_scale) {
  const double a0 = a, b0 = b;
  const double width_tolerance = kProjectionRelativeTolerance * (b - a);
  const Stationarity fa = stationarity(curve, x, a), fb = stationarity(curve, x, b);
  // With f(a) ≤ 0 ≤ f(b) the bracket holds a minimum and shrinks around it (rtsafe); otherwise the
  // minimum may sit at an end of the bracket and only descending steps are taken.
  const bool bracketed = fa.f <= 0.0 && fb.f >= 0.0;
  double u = seed;
  Stationarity s = stationarity(curve, x, u);
  const double seed_distance_squared = s.distance_squared;
  double lambda = 0.0;  // Levenberg–Marquardt damping, raised when a step fails to descend
  LocalResult result{u, s.distance_squared, 0, false};
  for (int it = 1; it <= kProjectionMaxIterations && !result.converged; ++it) {
    result.iterations = it;
    const double tolerance = stationarity_tolerance(s, x, length_scale);
    const bool at_end = (u - a <= width_tolerance && s.f > 0.0) || (b - u <= width_tolerance && s.f < 0.0);
    if (std::abs(s.f) <= tolerance || b - a <= width_tolerance || at_end) {
      result.converged = true;
      break;
    }
    if (bracketed) (s.f < 0.0 ? a : b) = u;
    double step;
    if (s.slope > 0.0) {
      step = -s.f / (s.slope + lambda);  // Newton (λ = 0) or damped Newton
    } else {
      // Not convex here: Gauss–Newton with Marquardt damping, a descent direction whatever C'' is.
      lambda = std::max(lambda, std::abs(s.slope));
      step = -s.f / (s.speed * s.speed + lambda);
    }
    double next = u + step;
    if (!(next > a && next < b)) next = bracketed ? 0.5 * (a + b) : std::clamp(next, a, b);
    const Stationarity t = stationarity(curve, x, next);
    if (bracketed || t.distance_squared <= s.distance_squared) {
      u = next;
      s = t;
      lambda *= 0.1;
    } else {
      lambda = std::max(4.0 * lambda, s.speed * s.speed);  // reject, damp harder
    }
  }
  result.u = u;
  result.distance_squared = s.distance_squared;
  if (!result.converged || s.distance_squared > seed_distance_squared) {
    const LocalResult g = golden_section(curve, x, a0, b0);
    if (g.distance_squared <= s.distance_squared) return {g.u, g.distance_squared, result.iterations + g.iterations, true};
  }
  return result;
}

// The seeding density when the caller does not choose one: 2p + 4 samples per span.
int samples_per_span_for(const ProjectionOptions& options, const SplineBasis& basis) {
  return options.samples_per_span > 0 ? options.samples_per_span : 2 * basis.degree() + 4;
}

// A table is used when it was built for this curve's spans with the sampling density asked for.
bool seeds_usable(const ProjectionOptions& options, const SplineCurve& curve, int per_span) {
  return options.seeds != nullptr && options.seeds->curve() == &curve && options.seeds->samples_per_span() == per_span;
}

}  // namespace

ProjectionSeeds::ProjectionSeeds(const SplineCurve& curve, int samples_per_span)
    : curve_(&curve), per_span_(samples_per_span_for(ProjectionOptions{.samples_per_span = samples_per_span}, curve.basis())),
      breaks_(curve.basis().breakpoints()) {
  for (size_t e = 0; e + 1 < breaks_.size(); ++e) {
    for (int q = 0; q < per_span_; ++q) points_.push_back(curve.point(breaks_[e] + (breaks_[e + 1] - breaks_[e]) * q / per_span_));
  }
}

Projection project(const SplineCurve& curve, const Eigen::Vector2d& x, const ProjectionOptions& options) {
  const SplineBasis& basis = curve.basis();
  if (!x.allFinite() || !(options.window_lo <= options.window_hi)) {
    Projection failed;
    failed.reason = "the point or its search window is not finite (a diverged iterate)";
    return failed;
  }
  // A window of more periods than this is a point absurdly far from the tool (a diverged iterate),
  // not a search to sample span by span.
  constexpr double kMaxWindowPeriods = 64.0;
  if (basis.is_periodic() && options.window_hi - options.window_lo > kMaxWindowPeriods * basis.period()) {
    Projection failed;
    failed.reason = "the point is more than " + std::to_string(static_cast<int>(kMaxWindowPeriods)) +
                    " periods from the curve (a diverged iterate)";
    return failed;
  }
  const int per_span = samples_per_span_for(options, basis);
  // Parameter range: open curves their domain; periodic curves with a shift a few periods around
  // the period the point's position along the shift falls into. Each span searched is a span of
  // the basis moved by a whole number of periods.
  struct Span {
    double a, b;
    int base, period;  // span `base` of [lo, hi], moved by `period` periods
  };
  const bool tabulated = seeds_usable(options, curve, per_span);
  std::vector<double> own_breaks;
  if (!tabulated) own_breaks = basis.breakpoints();
  const std::vector<double>& base_breaks = tabulated ? options.seeds->breaks() : own_breaks;
  const double period_length = basis.is_periodic() ? basis.period() : 0.0;
  std::vector<Span> spans;
  const auto add_periods = [&](int first, int last, bool (*keep)(double, double, const ProjectionOptions&)) {
    for (int q = first; q <= last; ++q) {
      const double offset = q * period_length;
      for (size_t e = 0; e + 1 < base_breaks.size(); ++e) {
        const double a = base_breaks[e] + offset, b = base_breaks[e + 1] + offset;
        if (keep(a, b, options)) spans.push_back({a, b, static_cast<int>(e), q});
      }
    }
  };
  const auto everything = [](double, double, const ProjectionOptions&) { return true; };
  const bool windowed = options.window_lo < options.window_hi;
  if (windowed) {
    // The spans meeting the window, continued periodically for periodic curves.
    const double lo0 = basis.lo();
    const int first = basis.is_periodic() ? static_cast<int>(std::floor((options.window_lo - lo0) / period_length)) : 0;
    const int last = basis.is_periodic() ? static_cast<int>(std::floor((options.window_hi - lo0) / period_length)) : 0;
    add_periods(first, last, [](double a, double b, const ProjectionOptions& o) { return !(b < o.window_lo || a > o.window_hi); });
    if (spans.empty()) add_periods(0, 0, everything);
  } else if (basis.is_periodic() && !curve.shift().isZero() && options.periods > 1) {
    const Eigen::Vector2d s = curve.shift();
    const double along = (x - curve.point(basis.lo())).dot(s) / s.squaredNorm();
    if (!(std::abs(along) < 1e9)) {
      Projection failed;
      failed.reason = "the point is too many periods from the curve (a diverged iterate)";
      return failed;
    }
    const int centre = static_cast<int>(std::floor(along));
    const int first = centre - (options.periods - 1) / 2;
    add_periods(first, first + options.periods - 1, everything);
  } else {
    add_periods(0, 0, everything);
  }
  if (spans.empty()) {  // a basis has at least one span; this states it for the reader and the compiler
    Projection failed;
    failed.reason = "the curve has no spans to search";
    return failed;
  }
  const double lo = spans.front().a, hi = spans.back().b;
  // Seeding: C at per_span points of every span, from the caller's table when it has one.
  std::vector<Sample> samples;
  samples.reserve(spans.size() * static_cast<size_t>(per_span) + 1);
  for (const Span& span : spans) {
    for (int q = 0; q < per_span; ++q) {
      const double u = span.a + (span.b - span.a) * q / per_span;
      const Eigen::Vector2d c = tabulated ? Eigen::Vector2d(options.seeds->point(span.base, q) + span.period * curve.shift())
                                          : curve.point(u);
      samples.push_back({u, (c - x).squaredNorm(), c});
    }
  }
  const Eigen::Vector2d c_hi = curve.point(hi);
  samples.push_back({hi, (c_hi - x).squaredNorm(), c_hi});
  const bool closed = basis.is_periodic() && curve.shift().isZero() && !windowed;
  const size_t count = samples.size();
  double length_scale = 0.0;
  for (size_t i = 1; i < count; ++i) {
    length_scale = std::max(length_scale, (samples[i].point - samples[i - 1].point).norm());
  }
  Projection out;
  out.distance = std::numeric_limits<double>::infinity();
  size_t best_sample = 0;
  for (size_t i = 0; i < count; ++i) {
    if (samples[i].distance_squared < samples[best_sample].distance_squared) best_sample = i;
  }
  // Every local minimum of the sampled distance is a candidate basin.
  for (size_t i = 0; i < count; ++i) {
    const bool has_left = i > 0 || closed, has_right = i + 1 < count || closed;
    const Sample& left = samples[i > 0 ? i - 1 : count - 2];
    const Sample& right = samples[i + 1 < count ? i + 1 : 1];
    if ((has_left && left.distance_squared < samples[i].distance_squared) ||
        (has_right && right.distance_squared < samples[i].distance_squared)) {
      continue;
    }
    const double a = has_left ? (i > 0 ? left.u : samples[count - 2].u - (hi - lo)) : samples[i].u;
    const double b = has_right ? (i + 1 < count ? right.u : samples[1].u + (hi - lo)) : samples[i].u;
    ++out.candidates;
    LocalResult r = a < b ? refine(curve, x, a, b, samples[i].u, length_scale)
                          : LocalResult{samples[i].u, samples[i].distance_squared, 0, true};
    if (r.distance_squared < out.distance * out.distance ||
        (r.distance_squared == out.distance * out.distance && r.u < out.u)) {
      out.u = r.u;
      out.distance = std::sqrt(r.distance_squared);
      out.iterations = r.iterations;
      out.converged = r.converged;
    }
  }
  if (out.candidates == 0 || !std::isfinite(out.distance)) {
    out.u = samples[best_sample].u;
    out.distance = std::sqrt(samples[best_sample].distance_squared);
    out.converged = false;
    out.reason = "no local minimum found among the samples; the best sample is returned";
  } else if (!out.converged) {
    out.reason = "the local iteration did not meet its tolerance in " + std::to_string(kProjectionMaxIterations) +
                 " iterations; the best iterate is returned";
  }
  out.foot = curve.point(out.u);
  return out;
}

}  // namespace mufric::spline
