#pragma once
// x ← exp(x) elementwise with glibc's libmvec vector exp (≤ 4 ulp) through the x86-64 vector function
// ABI, at the widest ISA the CPU running the code has (chosen once, at first use): AVX-512, AVX2, or
// the SSE2 baseline every x86-64 has. A portable build is therefore as fast here as a native one
// (measured, bench/studies/gp_evaluation/README.md). Every element goes through the same vector routine (a short tail
// is padded to a full vector), so exp(x_i) does not depend on i's position in the array: the same
// μ whatever batch or buffer a point is evaluated in.
#include <string_view>

#include <Eigen/Dense>

namespace mufric {

enum class VectorIsa { sse2, avx2, avx512 };
std::string_view to_string(VectorIsa isa);
// Whether this CPU runs `isa`; the widest it runs; what exp_in_place uses (the widest, unless the
// environment variable MUFRIC_VECTOR_ISA = sse2 | avx2 | avx512 asks for a narrower one).
bool cpu_supports(VectorIsa isa);
VectorIsa widest_vector_isa();
VectorIsa vector_isa_in_use();

// One of three builds of a kernel, for the ISA in use (kernels compiled per ISA with
// [[gnu::target(...)]] and picked once, e.g. into a function-local static).
template <typename Kernel>
Kernel kernel_for_isa_in_use(Kernel sse2, Kernel avx2, Kernel avx512) {
  switch (vector_isa_in_use()) {
    case VectorIsa::avx512: return avx512;
    case VectorIsa::avx2: return avx2;
    case VectorIsa::sse2: break;
  }
  return sse2;
}

void exp_in_place(double* x, Eigen::Index n);
// The same with a given ISA (for tests and benchmarks); throws Error if the CPU lacks it.
void exp_in_place(VectorIsa isa, double* x, Eigen::Index n);

}  // namespace mufric
