#include "surrogate/core/cholesky.hpp"

#include <cmath>

extern "C" {
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dpotri_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dtrtri_(const char* uplo, const char* diag, const int* n, double* a, const int* lda, int* info);
}

namespace mufric {

CholeskyOutcome cholesky_with_jitter(const Eigen::MatrixXd& source, double diagonal_shift, Eigen::MatrixXd& factor,
                                     const Eigen::VectorXd& per_point) {
  CholeskyOutcome outcome;
  const int n = static_cast<int>(source.rows());
  factor.resize(n, n);
  if (n == 0) {
    outcome.ok = true;
    return outcome;
  }
  if (per_point.size() != 0 && per_point.size() != n) {
    outcome.reason = "per-point variances: " + std::to_string(per_point.size()) + " for " + std::to_string(n) + " rows";
    return outcome;
  }
  const double mean_diagonal = source.diagonal().mean() + diagonal_shift + (per_point.size() ? per_point.mean() : 0.0);
  if (!std::isfinite(mean_diagonal) || mean_diagonal <= 0.0) {
    outcome.reason = "covariance diagonal is not positive and finite (mean " + std::to_string(mean_diagonal) + ")";
    return outcome;
  }
  const double jitter_cap = kJitterMaxRelative * mean_diagonal;
  double jitter = 0.0;
  while (true) {
    ++outcome.attempts;
    factor.triangularView<Eigen::Lower>() = source.triangularView<Eigen::Lower>();
    factor.diagonal().array() += diagonal_shift + jitter;
    if (per_point.size() != 0) factor.diagonal() += per_point;
    int info = 0;
    dpotrf_("L", &n, factor.data(), &n, &info);
    if (info == 0) {
      outcome.ok = true;
      outcome.jitter = jitter;
      factor.triangularView<Eigen::StrictlyUpper>().setZero();
      return outcome;
    }
    if (info < 0) {
      outcome.reason = "dpotrf rejected argument " + std::to_string(-info);
      return outcome;
    }
    const double next = jitter == 0.0 ? kJitterStartRelative * mean_diagonal : jitter * kJitterGrowth;
    if (next > jitter_cap * (1.0 + 1e-9)) {
      outcome.reason = "covariance matrix is not positive definite even with jitter " + std::to_string(jitter) +
                       " after " + std::to_string(outcome.attempts) + " attempts (leading minor " +
                       std::to_string(info) + " failed); inputs may be duplicated with conflicting outputs";
      return outcome;
    }
    jitter = next;
  }
}

bool inverse_from_cholesky(Eigen::MatrixXd& lower) {
  const int n = static_cast<int>(lower.rows());
  if (n == 0) return true;
  int info = 0;
  dpotri_("L", &n, lower.data(), &n, &info);
  return info == 0;
}

bool invert_lower_triangular(Eigen::MatrixXd& lower) {
  const int n = static_cast<int>(lower.rows());
  if (n == 0) return true;
  int info = 0;
  dtrtri_("L", "N", &n, lower.data(), &n, &info);
  lower.triangularView<Eigen::StrictlyUpper>().setZero();
  return info == 0;
}


}  // namespace mufric
