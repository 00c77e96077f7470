#include "surrogate/vector_exp.hpp"

#include <cmath>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

#if defined(__AVX512F__)
extern "C" __m512d _ZGVeN8v_exp(__m512d);  // glibc libmvec, AVX-512 variant
#elif defined(__AVX2__)
extern "C" __m256d _ZGVdN4v_exp(__m256d);  // glibc libmvec, AVX2 variant
#endif

namespace mufric {

void exp_in_place(double* x, Eigen::Index n) {
  Eigen::Index i = 0;
#if defined(__AVX512F__)
  for (; i + 8 <= n; i += 8) _mm512_storeu_pd(x + i, _ZGVeN8v_exp(_mm512_loadu_pd(x + i)));
#elif defined(__AVX2__)
  for (; i + 4 <= n; i += 4) _mm256_storeu_pd(x + i, _ZGVdN4v_exp(_mm256_loadu_pd(x + i)));
#endif
  if (i < n) {
    Eigen::Map<Eigen::ArrayXd> rest(x + i, n - i);
    rest = rest.exp();
  }
}

}  // namespace mufric
