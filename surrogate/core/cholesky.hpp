#pragma once
// Cholesky factorisation with bounded jitter escalation (as in albatross / libKriging), on
// LAPACK dpotrf/dpotri from OpenBLAS.
#include <string>

#include <Eigen/Dense>

#include "common/blas_threads.hpp"

namespace mufric {

// Jitter ladder, relative to the mean of the diagonal: start tiny, ×10 per retry, give up past the cap.
inline constexpr double kJitterStartRelative = 1e-12;
inline constexpr double kJitterGrowth = 10.0;
inline constexpr double kJitterMaxRelative = 1e-4;

struct CholeskyOutcome {
  bool ok = false;
  double jitter = 0.0;   // absolute value added to the diagonal (0 when none was needed)
  int attempts = 0;
  std::string reason;    // why it failed, when !ok
};

// Factorises A = S + shift·I + diag(per_point) (+ jitter·I when needed) into its lower factor, written
// to `factor`; only the lower triangle of `source` is read and it is left untouched, so retries
// start afresh. `per_point` (may be empty): a known variance per row, e.g. each sample's own noise.
CholeskyOutcome cholesky_with_jitter(const Eigen::MatrixXd& source, double diagonal_shift, Eigen::MatrixXd& factor,
                                     const Eigen::VectorXd& per_point = Eigen::VectorXd());

// Overwrites the lower factor L with the lower triangle of (L Lᵀ)⁻¹ (LAPACK dpotri).
bool inverse_from_cholesky(Eigen::MatrixXd& lower);

// Overwrites the lower-triangular `lower` with its inverse (LAPACK dtrtri); false if singular.
bool invert_lower_triangular(Eigen::MatrixXd& lower);

}  // namespace mufric
