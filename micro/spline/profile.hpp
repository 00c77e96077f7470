#pragma once
// Surface profiles: reading a measured one (CSV with units, e.g. a confocal microscope export),
// generating a synthetic rough one, its roughness figures, and a periodic least-squares spline fit.
#include <cstdint>
#include <string>
#include <vector>

#include "micro/spline/spline_curve.hpp"

namespace mufric::spline {

// One period of a profile: heights at increasing positions x; the profile repeats with `period`.
struct Profile {
  std::vector<double> x;       // m, strictly increasing, x.back() − x.front() < period
  std::vector<double> height;  // m
  double period = 0.0;         // m
  std::string source;
};

// A CSV with columns `x` and `height` and length units in the header, e.g. "x[um],height[um]".
// period_m = 0: one period sampled uniformly without repeating the first point, so period =
// (x_last − x_first)·m/(m − 1). Throws Error naming the file, line or column.
Profile read_profile_csv(const std::string& path, double period_m = 0.0);

// ISO 4287 figures of a profile's heights (after removing their mean): Ra (arithmetic mean
// deviation), Rq (root mean square), Rz (mean over five equal sampling lengths of the largest
// peak-to-valley height), and the autocorrelation length (first lag where the periodic
// autocorrelation drops to 1/e, interpolated linearly).
struct RoughnessFigures {
  double ra = 0.0, rq = 0.0, rz = 0.0, correlation_length = 0.0;  // m
};
RoughnessFigures roughness_figures(const Profile& profile);

// A periodic Gaussian random profile with a Gaussian autocorrelation R(τ) = Rq² exp(−τ²/λ²):
// a sum of cosines of every harmonic below Nyquist with amplitudes from its spectral density
// S(q) ∝ exp(−q²λ²/4) and random phases (spectral method, e.g. Persson et al., J. Phys. Condens.
// Matter 17, 2005, R1), sampled uniformly and scaled so that the sampled Ra is exactly `ra`.
struct RoughnessSpec {
  double length = 10e-6;              // m, the period (the paper's interval is 1e-5 m)
  double ra = 0.2e-6;                 // m
  double correlation_length = 1e-6;   // m, λ above
  int samples = 512;
  std::uint64_t seed = 1;
  bool operator==(const RoughnessSpec&) const = default;
};
Profile synthetic_rough_profile(const RoughnessSpec& spec);

// Periodic least-squares fit (Piegl & Tiller §9.4.1, with the periodic constraint built into the
// basis): chord-length parameters over one period including the closing chord, knots by averaging
// the parameters (P&T eq. 9.68–9.69 for periodic data), control points from a QR least-squares
// solve. The curve has shift (period, 0). Errors: distance between each data point and the curve at
// the point's parameter (an upper bound of the geometric distance).
struct ProfileFit {
  SplineCurve curve;
  std::vector<double> parameters;  // one per data point
  double rms_error = 0.0;          // m
  double max_error = 0.0;          // m
};
ProfileFit fit_periodic_profile(const Profile& profile, int degree, int control_points);

// The least-squares step on its own: the periodic curve of `basis` (shift per period `shift`)
// closest to `points` (one row per datum) at the given parameters. Throws Error if the system is
// rank-deficient (a basis function without data in its support).
SplineCurve fit_periodic_curve(const Points2& points, const std::vector<double>& parameters, const SplineBasis& basis,
                               const Eigen::Vector2d& shift);

}  // namespace mufric::spline
