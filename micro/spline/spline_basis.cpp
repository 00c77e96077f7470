#include "micro/spline/spline_basis.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/error.hpp"

namespace mufric::spline {
namespace {

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

void require(bool ok, const std::string& message) {
  if (!ok) throw Error("spline basis: " + message);
}

}  // namespace

SplineBasis::SplineBasis(int degree, std::vector<double> knots, bool periodic, double period)
    : degree_(degree), periodic_(periodic), period_(period), knots_(std::move(knots)) {
  require(degree_ >= 0 && degree_ <= kMaxDegree,
          "degree must lie in 0.." + std::to_string(kMaxDegree) + ", got " + std::to_string(degree_));
  for (size_t i = 0; i < knots_.size(); ++i) {
    require(std::isfinite(knots_[i]), "knot " + std::to_string(i) + " is not finite");
    require(i == 0 || knots_[i] >= knots_[i - 1], "knots must not decrease (knot " + std::to_string(i) + ")");
  }
  if (periodic_) {
    require(std::isfinite(period_) && period_ > 0.0, "the period must be positive");
    require(static_cast<int>(knots_.size()) >= degree_ + 1,
            "a periodic basis of degree " + std::to_string(degree_) + " needs at least " + std::to_string(degree_ + 1) +
                " knots per period, got " + std::to_string(knots_.size()));
    require(knots_.back() < knots_.front() + period_, "periodic knots must lie in [lo, lo + period)");
  } else {
    require(static_cast<int>(knots_.size()) >= 2 * degree_ + 2,
            "an open basis of degree " + std::to_string(degree_) + " needs at least " + std::to_string(2 * degree_ + 2) +
                " knots, got " + std::to_string(knots_.size()));
    require(lo() < hi(), "the domain [knot p, knot n] is empty");
  }
  // Within one period (periodic) or the whole vector (open), no knot repeats more than p + 1 times
  // (p times for periodic bases, which have no end knots).
  const int max_multiplicity = periodic_ ? std::max(degree_, 1) : degree_ + 1;
  for (const double u : breakpoints()) {
    require(multiplicity(u) <= max_multiplicity, "knot " + std::to_string(u) + " repeats " +
                                                     std::to_string(multiplicity(u)) + " times, more than " +
                                                     std::to_string(max_multiplicity));
  }
}

SplineBasis SplineBasis::open(int degree, std::vector<double> knots) {
  return SplineBasis(degree, std::move(knots), false, 0.0);
}

SplineBasis SplineBasis::open_uniform(int degree, int spans, double lo, double hi) {
  require(spans >= 1, "needs at least one span");
  std::vector<double> knots(static_cast<size_t>(degree), lo);
  for (int i = 0; i <= spans; ++i) knots.push_back(lo + (hi - lo) * i / spans);
  knots.back() = hi;
  knots.insert(knots.end(), static_cast<size_t>(degree), hi);
  return open(degree, std::move(knots));
}

SplineBasis SplineBasis::periodic(int degree, std::vector<double> period_knots, double period) {
  return SplineBasis(degree, std::move(period_knots), true, period);
}

SplineBasis SplineBasis::periodic_uniform(int degree, int spans, double lo, double hi) {
  require(spans >= 1, "needs at least one span");
  std::vector<double> knots;
  for (int i = 0; i < spans; ++i) knots.push_back(lo + (hi - lo) * i / spans);
  return periodic(degree, std::move(knots), hi - lo);
}

int SplineBasis::count() const {
  const int n = static_cast<int>(knots_.size());
  return periodic_ ? n : n - degree_ - 1;
}

double SplineBasis::lo() const { return periodic_ ? knots_.front() : knots_[static_cast<size_t>(degree_)]; }

double SplineBasis::hi() const {
  return periodic_ ? knots_.front() + period_ : knots_[static_cast<size_t>(count())];
}

double SplineBasis::tolerance() const { return kRelativeKnotTolerance * (hi() - lo()); }

double SplineBasis::knot(int j) const {
  if (!periodic_) return knots_[static_cast<size_t>(std::clamp(j, 0, static_cast<int>(knots_.size()) - 1))];
  const int n = static_cast<int>(knots_.size());
  const int q = floor_div(j, n);
  return knots_[static_cast<size_t>(j - q * n)] + q * period_;
}

std::vector<double> SplineBasis::breakpoints() const {
  std::vector<double> out;
  for (const double u : knots_) {
    if (u < lo() - tolerance() || u > hi() + tolerance()) continue;
    if (out.empty() || u - out.back() > tolerance()) out.push_back(u);
  }
  if (periodic_) out.push_back(hi());
  return out;
}

int SplineBasis::multiplicity(double u) const {
  int m = 0;
  for (const double t : knots_) m += std::abs(t - u) <= tolerance();
  return m;
}

SplineBasis::Location SplineBasis::locate(double u) const {
  Location at;
  if (periodic_) {
    at.periods = static_cast<int>(std::floor((u - lo()) / period_));
    at.u = u - at.periods * period_;
    if (at.u >= hi()) {  // rounding
      at.u -= period_;
      ++at.periods;
    }
    if (at.u < lo()) at.u = lo();
    at.span = static_cast<int>(std::upper_bound(knots_.begin(), knots_.end(), at.u) - knots_.begin()) - 1;
    return at;
  }
  at.u = std::clamp(u, lo(), hi());
  const int last = count() - 1;
  if (at.u >= hi()) {
    // The last non-empty span, closed at hi.
    at.span = last;
    while (knots_[static_cast<size_t>(at.span)] >= hi()) --at.span;
    return at;
  }
  at.span = static_cast<int>(std::upper_bound(knots_.begin(), knots_.begin() + last + 1, at.u) - knots_.begin()) - 1;
  at.span = std::max(at.span, degree_);
  return at;
}

int SplineBasis::function_index(int span, int j) const {
  const int i = span - degree_ + j;
  if (!periodic_) return i;
  const int n = count();
  return i - floor_div(i, n) * n;
}

int SplineBasis::function_period(int span, int j) const {
  return periodic_ ? floor_div(span - degree_ + j, count()) : 0;
}

BasisDerivatives SplineBasis::derivatives(int span, double u, int n) const {
  if (n < 0 || n > kMaxDegree) throw Error("spline basis: derivative order " + std::to_string(n) + " outside [0, " + std::to_string(kMaxDegree) + "]");
  const int p = degree_;
  const int k = span;
  BasisDerivatives ders = BasisDerivatives::Zero(n + 1, p + 1);
  // Fixed-capacity work arrays: no heap allocation per evaluation (assembly calls this per point).
  using Work = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDegree + 1, kMaxDegree + 1>;
  using WorkVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDegree + 1, 1>;
  Work ndu(p + 1, p + 1);
  WorkVector left(p + 1), right(p + 1);
  ndu(0, 0) = 1.0;
  for (int j = 1; j <= p; ++j) {
    left(j) = u - knot(k + 1 - j);
    right(j) = knot(k + j) - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu(j, r) = right(r + 1) + left(j - r);  // lower triangle: knot differences
      const double temp = ndu(r, j - 1) / ndu(j, r);
      ndu(r, j) = saved + right(r + 1) * temp;
      saved = left(j - r) * temp;
    }
    ndu(j, j) = saved;
  }
  for (int j = 0; j <= p; ++j) ders(0, j) = ndu(j, p);
  const int top = std::min(n, p);
  Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, kMaxDegree + 1> a(2, p + 1);
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a(0, 0) = 1.0;
    for (int kk = 1; kk <= top; ++kk) {
      double d = 0.0;
      const int rk = r - kk, pk = p - kk;
      if (r >= kk) {
        a(s2, 0) = a(s1, 0) / ndu(pk + 1, rk);
        d = a(s2, 0) * ndu(rk, pk);
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? kk - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a(s2, j) = (a(s1, j) - a(s1, j - 1)) / ndu(pk + 1, rk + j);
        d += a(s2, j) * ndu(rk + j, pk);
      }
      if (r <= pk) {
        a(s2, kk) = -a(s1, kk - 1) / ndu(pk + 1, r);
        d += a(s2, kk) * ndu(r, pk);
      }
      ders(kk, r) = d;
      std::swap(s1, s2);
    }
  }
  double factor = p;
  for (int kk = 1; kk <= top; ++kk) {
    ders.row(kk) *= factor;
    factor *= p - kk;
  }
  return ders;
}

Eigen::VectorXd SplineBasis::values(int span, double u) const { return derivatives(span, u, 0).row(0).transpose(); }

double SplineBasis::greville_abscissa(int i) const {
  if (degree_ == 0) return 0.5 * (knot(i) + knot(i + 1));
  double sum = 0.0;
  for (int j = 1; j <= degree_; ++j) sum += knot(i + j);
  return sum / degree_;
}

std::vector<double> SplineBasis::greville() const {
  std::vector<double> g(static_cast<size_t>(count()));
  for (int i = 0; i < count(); ++i) {
    const double u = greville_abscissa(i);
    g[static_cast<size_t>(i)] = periodic_ ? locate(u).u : u;
  }
  return g;
}

SplineBasis SplineBasis::with_knot(double u) const {
  std::vector<double> knots = knots_;
  if (periodic_) {
    u = locate(u).u;
  } else {
    require(u > lo() && u < hi(), "knot insertion at " + std::to_string(u) + " outside the open domain (" +
                                      std::to_string(lo()) + ", " + std::to_string(hi()) + ")");
  }
  knots.insert(std::upper_bound(knots.begin(), knots.end(), u), u);
  return SplineBasis(degree_, std::move(knots), periodic_, period_);
}

SplineBasis SplineBasis::elevated() const {
  std::vector<double> knots;
  for (size_t i = 0; i < knots_.size(); ++i) {
    knots.push_back(knots_[i]);
    const bool last_of_group = i + 1 == knots_.size() || knots_[i + 1] - knots_[i] > tolerance();
    if (last_of_group) knots.push_back(knots_[i]);
  }
  return SplineBasis(degree_ + 1, std::move(knots), periodic_, period_);
}

}  // namespace mufric::spline
