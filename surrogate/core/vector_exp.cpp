#include "surrogate/core/vector_exp.hpp"

#include <cstdlib>
#include <cstring>
#include <string>

#include <immintrin.h>

#include "common/error.hpp"

// glibc's libmvec entry points (x86-64 vector function ABI: b = SSE2, d = AVX2, e = AVX-512).
extern "C" __m128d _ZGVbN2v_exp(__m128d);
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4v_exp(__m256d);
extern "C" __attribute__((target("avx512f"))) __m512d _ZGVeN8v_exp(__m512d);

namespace mufric {
namespace {

// A tail shorter than a vector goes through the same routine in a zero-padded vector.
template <int Lanes, typename Kernel>
inline void padded_tail(double* x, Eigen::Index n, Kernel&& kernel) {
  alignas(64) double lane[Lanes] = {};
  std::memcpy(lane, x, static_cast<size_t>(n) * sizeof(double));
  kernel(lane);
  std::memcpy(x, lane, static_cast<size_t>(n) * sizeof(double));
}

void exp_sse2(double* x, Eigen::Index n) {
  const auto kernel = [](double* p) { _mm_storeu_pd(p, _ZGVbN2v_exp(_mm_loadu_pd(p))); };
  Eigen::Index i = 0;
  for (; i + 2 <= n; i += 2) kernel(x + i);
  if (i < n) padded_tail<2>(x + i, n - i, kernel);
}

__attribute__((target("avx2"))) void exp_avx2(double* x, Eigen::Index n) {
  const auto kernel = [](double* p) __attribute__((target("avx2"))) {
    _mm256_storeu_pd(p, _ZGVdN4v_exp(_mm256_loadu_pd(p)));
  };
  Eigen::Index i = 0;
  for (; i + 4 <= n; i += 4) kernel(x + i);
  if (i < n) padded_tail<4>(x + i, n - i, kernel);
}

__attribute__((target("avx512f"))) void exp_avx512(double* x, Eigen::Index n) {
  Eigen::Index i = 0;
  for (; i + 8 <= n; i += 8) _mm512_storeu_pd(x + i, _ZGVeN8v_exp(_mm512_loadu_pd(x + i)));
  if (i < n) {
    const auto mask = static_cast<__mmask8>((1u << (n - i)) - 1u);
    // Masked-off lanes hold 0 (exp(0) = 1): no spurious overflow flag.
    _mm512_mask_storeu_pd(x + i, mask, _ZGVeN8v_exp(_mm512_maskz_loadu_pd(mask, x + i)));
  }
}

VectorIsa choose_isa() {
  const VectorIsa widest = widest_vector_isa();
  const char* asked = std::getenv("MUFRIC_VECTOR_ISA");
  if (asked == nullptr || *asked == '\0') return widest;
  for (const VectorIsa isa : {VectorIsa::sse2, VectorIsa::avx2, VectorIsa::avx512}) {
    if (to_string(isa) == asked) return cpu_supports(isa) ? isa : widest;
  }
  return widest;  // an unknown name changes nothing
}

}  // namespace

std::string_view to_string(VectorIsa isa) {
  switch (isa) {
    case VectorIsa::sse2: return "sse2";
    case VectorIsa::avx2: return "avx2";
    case VectorIsa::avx512: return "avx512";
  }
  return "?";
}

bool cpu_supports(VectorIsa isa) {
  __builtin_cpu_init();
  switch (isa) {
    case VectorIsa::sse2: return true;  // part of x86-64
    case VectorIsa::avx2: return __builtin_cpu_supports("avx2") != 0;
    case VectorIsa::avx512: return __builtin_cpu_supports("avx512f") != 0;
  }
  return false;
}

VectorIsa widest_vector_isa() {
  if (cpu_supports(VectorIsa::avx512)) return VectorIsa::avx512;
  if (cpu_supports(VectorIsa::avx2)) return VectorIsa::avx2;
  return VectorIsa::sse2;
}

VectorIsa vector_isa_in_use() {
  static const VectorIsa chosen = choose_isa();
  return chosen;
}

void exp_in_place(VectorIsa isa, double* x, Eigen::Index n) {
  if (!cpu_supports(isa)) throw Error("this CPU has no " + std::string(to_string(isa)));
  switch (isa) {
    case VectorIsa::sse2: exp_sse2(x, n); return;
    case VectorIsa::avx2: exp_avx2(x, n); return;
    case VectorIsa::avx512: exp_avx512(x, n); return;
  }
}

void exp_in_place(double* x, Eigen::Index n) {
  static const auto kernel = kernel_for_isa_in_use(&exp_sse2, &exp_avx2, &exp_avx512);
  kernel(x, n);
}

}  // namespace mufric
