#include "micro/spline/profile.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "common/csv_table.hpp"
#include "common/error.hpp"

namespace mufric::spline {
namespace {

// Fewer samples than this cannot describe a profile, nor Rz's five sampling lengths.
constexpr size_t kMinimumProfileSamples = 10;

std::vector<double> centred(const std::vector<double>& h) {
  double mean = 0.0;
  for (const double v : h) mean += v;
  mean /= static_cast<double>(h.size());
  std::vector<double> out(h);
  for (double& v : out) v -= mean;
  return out;
}

}  // namespace

Profile read_profile_csv(const std::string& path, double period_m) {
  const CsvTable table = read_csv_table(path);
  Profile p;
  // Both are lengths: a header without a unit, or with another kind's (height[MPa]), is refused.
  p.x = table.si_column("x", QuantityKind::length);
  p.height = table.si_column("height", QuantityKind::length);
  p.source = path;
  if (p.x.size() < kMinimumProfileSamples) {
    throw Error(path + ": a profile needs at least " + std::to_string(kMinimumProfileSamples) + " rows, found " +
                std::to_string(p.x.size()));
  }
  for (size_t i = 1; i < p.x.size(); ++i) {
    if (!(p.x[i] > p.x[i - 1])) {
      throw Error(path + ":" + std::to_string(table.line_of_row[i]) + ": column x must increase strictly");
    }
  }
  const double span = p.x.back() - p.x.front();
  p.period = period_m > 0.0 ? period_m : span * static_cast<double>(p.x.size()) / static_cast<double>(p.x.size() - 1);
  if (!(p.period > span)) {
    throw Error(path + ": the period (" + std::to_string(p.period) + " m) must exceed the sampled range (" +
                std::to_string(span) + " m); the first point must not be repeated at the end");
  }
  return p;
}

RoughnessFigures roughness_figures(const Profile& profile) {
  const std::vector<double> h = centred(profile.height);
  const size_t m = h.size();
  RoughnessFigures f;
  for (const double v : h) {
    f.ra += std::abs(v);
    f.rq += v * v;
  }
  f.ra /= static_cast<double>(m);
  f.rq = std::sqrt(f.rq / static_cast<double>(m));
  constexpr int kSamplingLengths = 5;
  for (int s = 0; s < kSamplingLengths; ++s) {
    const size_t first = m * s / kSamplingLengths, last = m * (s + 1) / kSamplingLengths;
    const auto [lo, hi] = std::minmax_element(h.begin() + static_cast<long>(first), h.begin() + static_cast<long>(last));
    f.rz += (*hi - *lo) / kSamplingLengths;
  }
  // Periodic autocorrelation at lags of whole samples (uniform sampling assumed, as generated or
  // as a microscope exports).
  const double dx = profile.period / static_cast<double>(m);
  double previous = 1.0;
  const double r0 = f.rq * f.rq * static_cast<double>(m);
  for (size_t lag = 1; lag < m / 2; ++lag) {
    double r = 0.0;
    for (size_t i = 0; i < m; ++i) r += h[i] * h[(i + lag) % m];
    r /= r0;
    if (r <= std::exp(-1.0)) {
      const double fraction = (previous - std::exp(-1.0)) / (previous - r);
      f.correlation_length = (static_cast<double>(lag) - 1.0 + fraction) * dx;
      break;
    }
    previous = r;
  }
  return f;
}

Profile synthetic_rough_profile(const RoughnessSpec& spec) {
  if (!(spec.length > 0.0) || !(spec.ra > 0.0) || !(spec.correlation_length > 0.0)) {
    throw Error("rough profile: length, ra and correlation_length must be positive");
  }
  if (spec.samples < static_cast<int>(kMinimumProfileSamples)) {
    throw Error("rough profile: samples must be at least " + std::to_string(kMinimumProfileSamples));
  }
  const int m = spec.samples;
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  Profile p;
  p.period = spec.length;
  p.source = "synthetic (seed " + std::to_string(spec.seed) + ")";
  p.x.resize(static_cast<size_t>(m));
  p.height.assign(static_cast<size_t>(m), 0.0);
  for (int i = 0; i < m; ++i) p.x[static_cast<size_t>(i)] = spec.length * i / m;
  for (int k = 1; k < m / 2; ++k) {
    const double q = 2.0 * std::numbers::pi * k / spec.length;
    const double amplitude = std::exp(-q * q * spec.correlation_length * spec.correlation_length / 8.0);
    const double phi = phase(rng);
    for (int i = 0; i < m; ++i) p.height[static_cast<size_t>(i)] += amplitude * std::cos(q * p.x[static_cast<size_t>(i)] + phi);
  }
  p.height = centred(p.height);
  const double scale = spec.ra / roughness_figures(p).ra;
  for (double& h : p.height) h *= scale;
  return p;
}

ProfileFit fit_periodic_profile(const Profile& profile, int degree, int control_points) {
  const size_t m = profile.x.size();
  if (control_points < degree + 1) {
    throw Error("profile fit: " + std::to_string(control_points) + " control points cannot carry degree " +
                std::to_string(degree));
  }
  if (static_cast<size_t>(control_points) >= m) {
    throw Error("profile fit: " + std::to_string(control_points) + " control points need more than that many samples, " +
                profile.source + " has " + std::to_string(m));
  }
  const Eigen::Vector2d shift(profile.period, 0.0);
  // Chord-length parameters on [0, 1), the closing chord included.
  std::vector<double> u(m + 1, 0.0);
  for (size_t k = 1; k <= m; ++k) {
    const Eigen::Vector2d a(profile.x[k - 1], profile.height[k - 1]);
    const Eigen::Vector2d b = k < m ? Eigen::Vector2d(profile.x[k], profile.height[k])
                                    : Eigen::Vector2d(profile.x[0], profile.height[0]) + shift;
    u[k] = u[k - 1] + (b - a).norm();
  }
  for (double& v : u) v /= u[m];
  // Knots by averaging: knot j at the fractional data index j·m/n.
  const int n = control_points;
  std::vector<double> knots(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    const double d = static_cast<double>(j) * static_cast<double>(m) / n;
    const auto i = static_cast<size_t>(d);
    const double alpha = d - static_cast<double>(i);
    knots[static_cast<size_t>(j)] = (1.0 - alpha) * u[i] + alpha * u[i + 1];
  }
  const SplineBasis basis = SplineBasis::periodic(degree, knots, 1.0);
  Points2 data(static_cast<Eigen::Index>(m), 2);
  for (size_t k = 0; k < m; ++k) data.row(static_cast<Eigen::Index>(k)) << profile.x[k], profile.height[k];
  const std::vector<double> parameters(u.begin(), u.end() - 1);
  ProfileFit fit{fit_periodic_curve(data, parameters, basis, shift), parameters, 0.0, 0.0};
  for (size_t k = 0; k < m; ++k) {
    const double e = (fit.curve.point(u[k]) - Eigen::Vector2d(profile.x[k], profile.height[k])).norm();
    fit.rms_error += e * e;
    fit.max_error = std::max(fit.max_error, e);
  }
  fit.rms_error = std::sqrt(fit.rms_error / static_cast<double>(m));
  return fit;
}

SplineCurve fit_periodic_curve(const Points2& points, const std::vector<double>& parameters, const SplineBasis& basis,
                               const Eigen::Vector2d& shift) {
  const Eigen::Index m = points.rows();
  const int n = basis.count();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m, n);
  Points2 rhs(m, 2);
  for (Eigen::Index k = 0; k < m; ++k) {
    const auto at = basis.locate(parameters[static_cast<size_t>(k)]);
    const Eigen::VectorXd values = basis.values(at.span, at.u);
    Eigen::RowVector2d known_shift = Eigen::RowVector2d::Zero();
    for (int j = 0; j <= basis.degree(); ++j) {
      a(k, basis.function_index(at.span, j)) += values(j);
      known_shift += values(j) * (basis.function_period(at.span, j) + at.periods) * shift.transpose();
    }
    rhs.row(k) = points.row(k) - known_shift;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  if (qr.rank() < n) {
    throw Error("spline fit: the least-squares system has rank " + std::to_string(qr.rank()) + " < " +
                std::to_string(n) + " (some basis function has no data in its support); use fewer control points");
  }
  return SplineCurve(basis, qr.solve(rhs), {}, shift);
}

}  // namespace mufric::spline
