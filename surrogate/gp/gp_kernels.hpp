#pragma once
// The exact GP's per-query inner loops, compiled for AVX-512, AVX2 + FMA and the SSE2 baseline and
// chosen at run time with the vector exp (surrogate/core/vector_exp.hpp), so that a portable build runs
// them at the width of the CPU it is on. Plain loops: Eigen's packets are fixed at compile time.
#include <Eigen/Core>

namespace mufric::gp_kernels {

// out_i = max(−½ Σ_k (a_ik − q_k)², floor) for the n × d column-major a: the RBF exponent of a query
// against every training point (inputs already divided by the length scales).
void rbf_exponents(const double* a, Eigen::Index n, Eigen::Index d, const double* q, double floor, double* out);

// Σ a_i b_i in kLanes interleaved partial sums added pairwise at the end: the result does not depend
// on where a and b start (Eigen's packet reduction peels up to the first aligned element).
inline constexpr Eigen::Index kLanes = 32;
double lane_dot(const double* a, const double* b, Eigen::Index n);

}  // namespace mufric::gp_kernels
