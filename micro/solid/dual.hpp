#pragma once
// Forward-mode automatic differentiation with N directional derivatives (dual numbers; Griewank &
// Walther, Evaluating Derivatives, 2nd ed. 2008, ch. 3). The materials use it to obtain their
// consistent tangent as the exact derivative of the discrete stress update.
#include <cmath>

#include <Eigen/Dense>

namespace mufric::solid {

template <int N>
struct Dual {
  double v = 0.0;
  Eigen::Matrix<double, N, 1> d = Eigen::Matrix<double, N, 1>::Zero();

  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants convert implicitly
  static Dual variable(double value, int direction) {
    Dual x(value);
    x.d(direction) = 1.0;
    return x;
  }
  Dual& operator+=(const Dual& o) { v += o.v; d += o.d; return *this; }
  Dual& operator-=(const Dual& o) { v -= o.v; d -= o.d; return *this; }
  Dual& operator*=(const Dual& o) { d = d * o.v + o.d * v; v *= o.v; return *this; }
  Dual& operator/=(const Dual& o) { d = (d * o.v - o.d * v) / (o.v * o.v); v /= o.v; return *this; }
};

template <int N> Dual<N> operator+(Dual<N> a, const Dual<N>& b) { return a += b; }
template <int N> Dual<N> operator-(Dual<N> a, const Dual<N>& b) { return a -= b; }
template <int N> Dual<N> operator*(Dual<N> a, const Dual<N>& b) { return a *= b; }
template <int N> Dual<N> operator/(Dual<N> a, const Dual<N>& b) { return a /= b; }
template <int N> Dual<N> operator+(Dual<N> a, double b) { a.v += b; return a; }
template <int N> Dual<N> operator+(double b, Dual<N> a) { a.v += b; return a; }
template <int N> Dual<N> operator-(Dual<N> a, double b) { a.v -= b; return a; }
template <int N> Dual<N> operator-(double b, Dual<N> a) { a.v = b - a.v; a.d = -a.d; return a; }
template <int N> Dual<N> operator-(Dual<N> a) { a.v = -a.v; a.d = -a.d; return a; }
template <int N> Dual<N> operator*(Dual<N> a, double b) { a.v *= b; a.d *= b; return a; }
template <int N> Dual<N> operator*(double b, Dual<N> a) { a.v *= b; a.d *= b; return a; }
template <int N> Dual<N> operator/(Dual<N> a, double b) { a.v /= b; a.d /= b; return a; }
template <int N> Dual<N> operator/(double b, const Dual<N>& a) {
  Dual<N> r(b / a.v);
  r.d = -b / (a.v * a.v) * a.d;
  return r;
}
template <int N> Dual<N> log(const Dual<N>& a) { Dual<N> r(std::log(a.v)); r.d = a.d / a.v; return r; }
template <int N> Dual<N> exp(const Dual<N>& a) { Dual<N> r(std::exp(a.v)); r.d = r.v * a.d; return r; }
template <int N> Dual<N> sqrt(const Dual<N>& a) { Dual<N> r(std::sqrt(a.v)); r.d = a.d / (2.0 * r.v); return r; }

inline double value(double x) { return x; }
template <int N> double value(const Dual<N>& x) { return x.v; }

}  // namespace mufric::solid
