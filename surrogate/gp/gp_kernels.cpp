#include "surrogate/gp/gp_kernels.hpp"

#include <algorithm>

#include "surrogate/core/vector_exp.hpp"

namespace mufric::gp_kernels {
namespace {

// The bodies, inlined into one wrapper per ISA (GCC vectorises each for its wrapper's target).
[[gnu::always_inline]] inline void rbf_exponents_body(const double* a, Eigen::Index n, Eigen::Index d, const double* q,
                                                      double floor, double* out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = a[i] - q[0];
    out[i] = t * t;
  }
  for (Eigen::Index k = 1; k < d; ++k) {
    const double* column = a + k * n;
    const double qk = q[k];
    for (Eigen::Index i = 0; i < n; ++i) {
      const double t = column[i] - qk;
      out[i] += t * t;
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double e = -0.5 * out[i];
    out[i] = e > floor ? e : floor;
  }
}

[[gnu::always_inline]] inline double lane_dot_body(const double* a, const double* b, Eigen::Index n) {
  double lane[kLanes] = {};
  Eigen::Index i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (Eigen::Index l = 0; l < kLanes; ++l) lane[l] += a[i + l] * b[i + l];
  }
  // The tail a vector at a time where it can (a triangular row's tail averages kLanes / 2 terms).
  constexpr Eigen::Index kTailLanes = 8;
  for (; i + kTailLanes <= n; i += kTailLanes) {
    for (Eigen::Index l = 0; l < kTailLanes; ++l) lane[l] += a[i + l] * b[i + l];
  }
  for (Eigen::Index l = 0; i < n; ++i, ++l) lane[l] += a[i] * b[i];
  for (Eigen::Index width = kLanes / 2; width > 0; width /= 2) {
    for (Eigen::Index l = 0; l < width; ++l) lane[l] += lane[l + width];
  }
  return lane[0];
}

void rbf_exponents_sse2(const double* a, Eigen::Index n, Eigen::Index d, const double* q, double floor, double* out) {
  rbf_exponents_body(a, n, d, q, floor, out);
}
[[gnu::target("avx2,fma")]] void rbf_exponents_avx2(const double* a, Eigen::Index n, Eigen::Index d, const double* q,
                                                    double floor, double* out) {
  rbf_exponents_body(a, n, d, q, floor, out);
}
[[gnu::target("avx512f,fma")]] void rbf_exponents_avx512(const double* a, Eigen::Index n, Eigen::Index d,
                                                         const double* q, double floor, double* out) {
  rbf_exponents_body(a, n, d, q, floor, out);
}

double lane_dot_sse2(const double* a, const double* b, Eigen::Index n) { return lane_dot_body(a, b, n); }
[[gnu::target("avx2,fma")]] double lane_dot_avx2(const double* a, const double* b, Eigen::Index n) {
  return lane_dot_body(a, b, n);
}
[[gnu::target("avx512f,fma")]] double lane_dot_avx512(const double* a, const double* b, Eigen::Index n) {
  return lane_dot_body(a, b, n);
}

}  // namespace

void rbf_exponents(const double* a, Eigen::Index n, Eigen::Index d, const double* q, double floor, double* out) {
  static const auto kernel = kernel_for_isa_in_use(&rbf_exponents_sse2, &rbf_exponents_avx2, &rbf_exponents_avx512);
  kernel(a, n, d, q, floor, out);
}

double lane_dot(const double* a, const double* b, Eigen::Index n) {
  static const auto kernel = kernel_for_isa_in_use(&lane_dot_sse2, &lane_dot_avx2, &lane_dot_avx512);
  return kernel(a, b, n);
}

}  // namespace mufric::gp_kernels
