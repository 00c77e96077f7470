#include "surrogate/gp/gaussian_process.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "common/blas_threads.hpp"
#include "common/environment.hpp"
#include "common/error.hpp"
#include "surrogate/core/cholesky.hpp"
#include "surrogate/fast/fast_evaluator.hpp"
#include "surrogate/fast/fast_path.hpp"
#include "surrogate/gp/gp_kernels.hpp"
#include "surrogate/core/vector_exp.hpp"

// BLAS dtrmm (OpenBLAS): B ← α op(A) B with A triangular.
extern "C" void dtrmm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
                       const double* alpha, const double* a, const int* lda, double* b, const int* ldb);

namespace mufric {
namespace {

// Queries per block: the n × block kernel slab stays in L2 for n ≈ 1000 while the triangular solve
// still runs as a matrix–matrix (level-3) operation.
constexpr Eigen::Index kQueryBlock = kEvaluationBlockRows;  // the one block size (friction_model.hpp)
// Below this many queries a parallel region costs more than it saves.
constexpr Eigen::Index kParallelThreshold = 2 * kQueryBlock;
// Up to this many queries with a variance read L⁻¹ row by row once for all of them (memory-bound,
// split over two cores' L2 caches); larger blocks use a triangular matrix product (compute-bound).
constexpr Eigen::Index kRowByRowMaxQueries = 16;
// An L⁻¹ larger than this (bytes of its lower half) is split over two threads for a single query,
// so that each half stays in one core's L2 cache.
constexpr double kSplitRowsAboveBytes = 512.0 * 1024.0;

// exp(−½ r²) is floored at e^−345 ≈ 1e-150: far below the rounding of any sum it enters, and it
// keeps kernel values and their pairwise products (Cholesky updates, triangular solves) out of the
// subnormal range, where x86 arithmetic is ~100× slower (a length scale of 0.01 box widths made
// LML evaluations 3.5× slower before).
constexpr double kMinimumExponent = -345.0;

}  // namespace

Eigen::VectorXd GpHyperParameters::to_log() const {
  Eigen::VectorXd theta(count());
  theta(0) = std::log(signal_variance);
  theta.segment(1, length_scales.size()) = length_scales.array().log();
  if (noise_term) theta(theta.size() - 1) = std::log(noise_variance);
  return theta;
}

GpHyperParameters GpHyperParameters::from_log(const Eigen::VectorXd& theta, Eigen::Index dims, bool noise_term) {
  GpHyperParameters h;
  h.signal_variance = std::exp(theta(0));
  h.length_scales = theta.segment(1, dims).array().exp();
  h.noise_term = noise_term;
  h.noise_variance = noise_term ? std::exp(theta(dims + 1)) : 0.0;
  return h;
}

Eigen::MatrixXd to_unit_box(const Eigen::MatrixXd& x, const InputSpace& inputs) {
  Eigen::MatrixXd u(x.rows(), x.cols());
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    const InputSpec& input = inputs[static_cast<size_t>(j)];
    u.col(j) = (x.col(j).array() - input.lo) / (input.hi - input.lo);
  }
  return u;
}

void rbf_correlation_in_place(Eigen::Ref<Eigen::ArrayXd> values) {
  values = (-0.5 * values).max(kMinimumExponent);
  exp_in_place(values.data(), values.size());
}

Eigen::MatrixXd rbf_correlations(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd k(a.rows(), b.rows());
  for (Eigen::Index j = 0; j < b.rows(); ++j) k.col(j) = (a.rowwise() - b.row(j)).rowwise().squaredNorm();
  rbf_correlation_in_place(Eigen::Map<Eigen::ArrayXd>(k.data(), k.size()));
  return k;
}

void rbf_signal_covariance(const Eigen::MatrixXd& x_unit, const GpHyperParameters& hyper, Eigen::MatrixXd& kf) {
  const Eigen::Index n = x_unit.rows();
  const Eigen::MatrixXd scaled = x_unit * hyper.length_scales.cwiseInverse().asDiagonal();
  kf.resize(n, n);
  Eigen::ArrayXd r2(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::Index len = n - j;
    r2.head(len).setZero();
    for (Eigen::Index k = 0; k < scaled.cols(); ++k) {
      r2.head(len) += (scaled.col(k).tail(len).array() - scaled(j, k)).square();
    }
    rbf_correlation_in_place(r2.head(len));
    kf.col(j).tail(len) = hyper.signal_variance * r2.head(len);
  }
}

GaussianProcess::GaussianProcess(State state) : FrictionModel(state.inputs), state_(std::move(state)) {
  const auto n = state_.x_train.rows();
  const auto d = static_cast<Eigen::Index>(state_.inputs.size());
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error("Gaussian process: " + what);
  };
  require(n > 0, "no training points");
  require(state_.x_train.cols() == d, "x_train has " + std::to_string(state_.x_train.cols()) + " columns for " +
                                          std::to_string(d) + " inputs");
  require(state_.y_train.size() == n, "y_train length differs from x_train rows");
  require(state_.alpha.size() == n, "alpha length differs from the number of training points");
  require(state_.cholesky.rows() == n && state_.cholesky.cols() == n, "cholesky factor is not n × n");
  require(state_.hyper.length_scales.size() == d, "length_scales has the wrong length");
  require(state_.hyper.length_scales.allFinite() && (state_.hyper.length_scales.array() > 0).all(),
          "length_scales must be positive and finite");
  require(std::isfinite(state_.hyper.signal_variance) && state_.hyper.signal_variance > 0, "signal_variance must be positive");
  require(std::isfinite(state_.hyper.noise_variance) && state_.hyper.noise_variance >= 0, "noise_variance must be >= 0");
  require(std::isfinite(state_.y_scale) && state_.y_scale > 0, "y_scale must be positive");
  require(std::isfinite(state_.y_mean), "y_mean must be finite");
  require(state_.alpha.allFinite() && state_.x_train.allFinite() && state_.y_train.allFinite(), "non-finite training data or alpha");
  require(state_.known_noise.size() == 0 || state_.known_noise.size() == n, "known_noise length differs from the training points");
  require(state_.known_noise.allFinite() && (state_.known_noise.array() >= 0).all(), "known_noise must be finite and >= 0");
  require(std::isfinite(state_.micro_std_error) && state_.micro_std_error >= 0, "micro_std_error must be finite and >= 0");

  box_lo_.resize(d);
  inverse_box_width_.resize(d);
  for (Eigen::Index j = 0; j < d; ++j) {
    box_lo_(j) = state_.inputs[static_cast<size_t>(j)].lo;
    inverse_box_width_(j) = 1.0 / (state_.inputs[static_cast<size_t>(j)].hi - state_.inputs[static_cast<size_t>(j)].lo);
  }
  scaled_train_ = to_unit_box(state_.x_train, state_.inputs) * state_.hyper.length_scales.cwiseInverse().asDiagonal();
  weights_ = state_.y_scale * state_.hyper.signal_variance * state_.alpha;
  Eigen::MatrixXd inverse = state_.cholesky;
  require(invert_lower_triangular(inverse), "cholesky factor is singular");
  inverse_factor_ = inverse;
  row_split_ = static_cast<Eigen::Index>(static_cast<double>(n) / std::sqrt(2.0));
  weights_by_input_ = scaled_train_.array().colwise() * weights_.array();
  if (state_.mean_estimated) {
    trend_direction_ = inverse_factor_.triangularView<Eigen::Lower>() * Eigen::VectorXd::Ones(n);
    trend_precision_ = trend_direction_.squaredNorm();
    require(std::isfinite(trend_precision_) && trend_precision_ > 0.0, "the estimated mean's precision 1ᵀK⁻¹1 is not positive");
  }
}

double GaussianProcess::normalised_variance(double squared_norm, double trend_dot) const {
  // σ² + σn² − σ⁴ |L⁻¹ k̂|²  (R&W Algorithm 2.1, lines 5–6), plus the micro-model's own scatter
  // (State::micro_std_error), or σ² alone for the mean over draws; plus an estimated mean's variance
  // (1 − σ² 1ᵀK⁻¹k̂)² / 1ᵀK⁻¹1 (State::mean_estimated).
  const double s2 = state_.hyper.signal_variance;
  const double scatter = state_.micro_std_error / state_.y_scale;
  const double prior = state_.interval_of_mean ? s2 : s2 + state_.hyper.noise_variance + scatter * scatter;
  double variance = prior - s2 * s2 * squared_norm;
  if (state_.mean_estimated) {
    const double unexplained = 1.0 - s2 * trend_dot;
    variance += unexplained * unexplained / trend_precision_;
  }
  return variance;
}

void GaussianProcess::correlations_with_training(const Eigen::RowVectorXd& scaled_query,
                                                 Eigen::Ref<Eigen::ArrayXd> correlation) const {
  gp_kernels::rbf_exponents(scaled_train_.data(), scaled_train_.rows(), scaled_train_.cols(), scaled_query.data(),
                            kMinimumExponent, correlation.data());
  exp_in_place(correlation.data(), correlation.size());
}

double GaussianProcess::mean_from_correlations(const double* correlation) const {
  return state_.y_mean + gp_kernels::lane_dot(correlation, weights_.data(), weights_.size());
}

void GaussianProcess::evaluate_block(const QueryBatch& x, Eigen::Index first, Eigen::Index count,
                                     const EvaluationRequest& what, Eigen::MatrixXd& k_block, Eigen::MatrixXd& v_block,
                                     Evaluation& out, long long& clamped) const {
  const Eigen::Index d = scaled_train_.cols();
  const Eigen::MatrixXd q = scaled_queries(x.middleRows(first, count));
  const bool need_std = what.std || what.ci_level > 0.0;
  // Column b of k_block: query b's correlations with every training point; a mean-only request
  // stores none (each query's correlations and dot product stay in L1).
  means_and_correlations(q, out.mu.segment(first, count), need_std || what.gradient ? &k_block : nullptr);
  if (!need_std && !what.gradient) return;

  if (what.gradient) {
    // ∂μ/∂x_k = −Σ_i w_i k_i (q_k − s_ik) / (l_k · width_k)  with s = scaled training inputs.
    const Eigen::MatrixXd weighted = k_block.transpose() * weights_by_input_;  // count × d
    for (Eigen::Index k = 0; k < d; ++k) {
      const double factor = inverse_box_width_(k) / state_.hyper.length_scales(k);
      for (Eigen::Index b = 0; b < count; ++b) {
        const double kw = out.mu(first + b) - state_.y_mean;
        out.gradient(first + b, k) = -factor * (q(b, k) * kw - weighted(b, k));
      }
    }
  }

  if (need_std) {
    Eigen::Matrix<double, 2, Eigen::Dynamic> norms;
    if (count <= kRowByRowMaxQueries) {
      norms = norms_row_by_row(k_block, what.max_threads);
    } else {
      whiten_block(k_block, v_block);
      norms.resize(2, count);
      norms.row(0) = v_block.leftCols(count).colwise().squaredNorm();
      if (state_.mean_estimated) {
        norms.row(1) = trend_direction_.transpose() * v_block.leftCols(count);
      } else {
        norms.row(1).setZero();
      }
    }
    for (Eigen::Index b = 0; b < count; ++b) {
      double variance = normalised_variance(norms(0, b), norms(1, b));
      if (variance < 0.0) {
        variance = 0.0;
        ++clamped;
      }
      out.std(first + b) = state_.y_scale * std::sqrt(variance);
    }
  }
}

void GaussianProcess::whiten_block(const Eigen::Ref<const Eigen::MatrixXd>& k_block, Eigen::MatrixXd& v_block) const {
#if defined(__AVX2__)
  // A build for a vector ISA (MUFRIC_NATIVE): Eigen's product, compiled for it, is the faster one
  // (1.45× OpenBLAS's dtrmm on one AVX-512 core at n = 900; bench/studies/gp_evaluation/README.md).
  v_block.noalias() = inverse_factor_.triangularView<Eigen::Lower>() * k_block;
#else
  // A portable build: OpenBLAS's dtrmm, whose kernels are chosen for the CPU at load time (2.6×
  // Eigen's SSE2 product on an AVX-512 core). One BLAS thread: the team is the parallelism.
  // L⁻¹ is stored row-major: read column-major it is its transpose, upper triangular. OpenBLAS
  // rounds a column differently depending on how many columns it is given (its edge tiles), so
  // every call gets a full block, zero-padded: a query's σ is then the same bits in any batch,
  // as with Eigen's product (the service's transports agree to the bit; tested).
  const Eigen::Index n = k_block.rows();
  v_block.setZero(n, kQueryBlock);
  v_block.leftCols(k_block.cols()) = k_block;
  const char side = 'L', upper = 'U', transpose = 'T', non_unit = 'N';
  const int rows = static_cast<int>(n), columns = static_cast<int>(kQueryBlock);
  const double one = 1.0;
  dtrmm_(&side, &upper, &transpose, &non_unit, &rows, &columns, &one, inverse_factor_.data(), &rows, v_block.data(), &rows);
#endif
}

Eigen::MatrixXd GaussianProcess::scaled_queries(const Eigen::MatrixXd& x) const {
  return ((x.rowwise() - box_lo_).array().rowwise() * inverse_box_width_.array()).matrix() *
         state_.hyper.length_scales.cwiseInverse().asDiagonal();
}

void GaussianProcess::means_and_correlations(const Eigen::MatrixXd& scaled, Eigen::Ref<Eigen::VectorXd> mean,
                                             Eigen::MatrixXd* correlations) const {
  const Eigen::Index n = scaled_train_.rows();
  if (correlations != nullptr) correlations->resize(n, scaled.rows());
  // Each row's correlations are computed in an aligned buffer, then copied: exp over a column that
  // starts anywhere takes a scalar head in a portable build and would round differently.
  Eigen::ArrayXd correlation(n);
  for (Eigen::Index b = 0; b < scaled.rows(); ++b) {
    correlations_with_training(scaled.row(b), correlation);
    mean(b) = mean_from_correlations(correlation.data());
    if (correlations != nullptr) correlations->col(b) = correlation.matrix();
  }
}

Eigen::VectorXd GaussianProcess::latent_mean(const Eigen::MatrixXd& x) const {
  require_query_columns(x);
  Eigen::VectorXd mean(x.rows());
  means_and_correlations(scaled_queries(x), mean, nullptr);
  return mean;
}

GaussianProcess::LatentPoints GaussianProcess::latent_points(const Eigen::MatrixXd& x) const {
  require_query_columns(x);
  LatentPoints out;
  out.scaled = scaled_queries(x);
  out.mean.resize(x.rows());
  Eigen::MatrixXd correlations;
  means_and_correlations(out.scaled, out.mean, &correlations);
  if (x.rows() <= kLatentSmallBatch) {
    out.whitened.noalias() = inverse_factor_.triangularView<Eigen::Lower>() * correlations;
    return out;
  }
  out.whitened.resize(correlations.rows(), x.rows());
  Eigen::MatrixXd v_block;
  for (Eigen::Index first = 0; first < x.rows(); first += kQueryBlock) {
    const Eigen::Index count = std::min(kQueryBlock, x.rows() - first);
    whiten_block(correlations.middleCols(first, count), v_block);
    out.whitened.middleCols(first, count) = v_block.leftCols(count);
  }
  return out;
}

Eigen::RowVectorXd GaussianProcess::unexplained_trend(const Eigen::MatrixXd& whitened) const {
  if (!state_.mean_estimated) return {};
  return (1.0 - state_.hyper.signal_variance * (trend_direction_.transpose() * whitened).array()).matrix();
}

Eigen::MatrixXd GaussianProcess::latent_covariance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) const {
  const LatentPoints pa = latent_points(a);
  return &a == &b ? latent_covariance(pa, pa) : latent_covariance(pa, latent_points(b));
}

Eigen::MatrixXd GaussianProcess::latent_covariance(const LatentPoints& a, const LatentPoints& b) const {
  const double s2 = state_.hyper.signal_variance;
  Eigen::MatrixXd covariance = s2 * rbf_correlations(a.scaled, b.scaled);
  covariance.noalias() -= (s2 * s2) * a.whitened.transpose() * b.whitened;
  if (state_.mean_estimated) {
    covariance.noalias() += unexplained_trend(a.whitened).transpose() * unexplained_trend(b.whitened) / trend_precision_;
  }
  return state_.y_scale * state_.y_scale * covariance;
}

Eigen::MatrixXd GaussianProcess::latent_covariance(const Eigen::MatrixXd& x) const { return latent_covariance(x, x); }

Eigen::VectorXd GaussianProcess::latent_variance(const Eigen::MatrixXd& x) const { return latent_variance(latent_points(x)); }

Eigen::VectorXd GaussianProcess::latent_variance(const LatentPoints& x) const {
  const Eigen::MatrixXd& v = x.whitened;
  const double s2 = state_.hyper.signal_variance;
  Eigen::ArrayXd variance = s2 - s2 * s2 * v.colwise().squaredNorm().transpose().array();
  if (state_.mean_estimated) variance += unexplained_trend(v).transpose().array().square() / trend_precision_;
  return state_.y_scale * state_.y_scale * variance.matrix();
}

void GaussianProcess::require_query_columns(const Eigen::MatrixXd& x) const {
  if (x.cols() != scaled_train_.cols()) {
    throw Error("Gaussian process: points have " + std::to_string(x.cols()) + " columns for " +
                std::to_string(scaled_train_.cols()) + " inputs");
  }
}

int evaluation_team_size(int max_threads) {
  // Called from a thread of the caller's own parallel region (a meso code's OpenMP loop over its
  // contact blocks), a team of our own would oversubscribe the cores: evaluate on the calling thread.
  // A region of one thread is not active (OpenMP's own rule): the other cores are idle and a team
  // may use them (1.9× faster at n = 900 in examples/c/meso_loop.c; bench/studies/meso_calls/README.md).
  if (omp_in_parallel()) return 1;
  // OpenMP's limit follows the affinity mask but not an OMP_NUM_THREADS above it; usable_cores()
  // honours both. Read once: this is on every call's path, and the mask of a running code is fixed.
  static const int cores = usable_cores();
  const int available = std::min(omp_get_max_threads(), cores);
  return max_threads > 0 ? std::min(max_threads, available) : available;
}

Eigen::Matrix<double, 2, Eigen::Dynamic> GaussianProcess::norms_row_by_row(const Eigen::MatrixXd& kernels,
                                                                            int max_threads) const {
  const Eigen::Index n = scaled_train_.rows();
  const Eigen::Index count = kernels.cols();
  const bool trend = state_.mean_estimated;
  auto rows = [&](Eigen::Index begin, Eigen::Index end) {
    Eigen::Matrix<double, 2, Eigen::Dynamic> sums = Eigen::Matrix<double, 2, Eigen::Dynamic>::Zero(2, count);
    if (count == 1) {  // a plain dot product per row: no matrix–vector call overhead
      for (Eigen::Index i = begin; i < end; ++i) {
#if defined(__AVX2__)
        // A build for a vector ISA: Eigen's dot, compiled for it (1.2× lane_dot at n = 900).
        const double v = inverse_factor_.row(i).head(i + 1).dot(kernels.col(0).head(i + 1).transpose());
#else
        // A portable build: the run-time-dispatched kernel (1.4× Eigen's SSE2 dot on AVX-512).
        const double v = gp_kernels::lane_dot(inverse_factor_.row(i).data(), kernels.col(0).data(), i + 1);
#endif
        sums(0, 0) += v * v;
        if (trend) sums(1, 0) += trend_direction_(i) * v;
      }
      return sums;
    }
    Eigen::RowVectorXd v(count);
    for (Eigen::Index i = begin; i < end; ++i) {
      v.noalias() = inverse_factor_.row(i).head(i + 1) * kernels.topRows(i + 1);
      sums.row(0) += v.cwiseAbs2();
      if (trend) sums.row(1) += trend_direction_(i) * v;
    }
    return sums;
  };
  const double bytes = 4.0 * static_cast<double>(n) * static_cast<double>(n);
  if (bytes <= kSplitRowsAboveBytes || evaluation_team_size(max_threads) < 2) return rows(0, n);
  Eigen::Matrix<double, 2, Eigen::Dynamic> halves[2];
#pragma omp parallel num_threads(2)
  {
    const int t = omp_get_thread_num();
    halves[t] = t == 0 ? rows(0, row_split_) : rows(row_split_, n);
  }
  return halves[0] + halves[1];
}

void GaussianProcess::attach_fast_evaluator(std::shared_ptr<const FastEvaluator> fast) {
  if (fast && !same_input_space(fast->box(), inputs())) {
    throw Error("fast evaluator: its box is not the model's training box");
  }
  fast_ = std::move(fast);
}

void GaussianProcess::evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  evaluate_through_grid(
      fast_.get(), x, what, [this](const QueryBatch& rows, const EvaluationRequest& w, Evaluation& e) { evaluate_exact(rows, w, e); },
      out);
}

void GaussianProcess::evaluate_exact(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  const Eigen::Index m = x.rows();
  out.mu.resize(m);
  if (what.std || what.ci_level > 0.0) out.std.resize(m);
  if (what.gradient) out.gradient.resize(m, x.cols());
  const Eigen::Index blocks = (m + kQueryBlock - 1) / kQueryBlock;
  const int team = evaluation_team_size(what.max_threads);
#if !defined(__AVX2__)
  // Our team (or the caller's) is the parallelism: each block's dtrmm runs on its own thread.
  std::optional<SingleThreadedBlas> one_blas_thread;
  if ((what.std || what.ci_level > 0.0) && m > kRowByRowMaxQueries) one_blas_thread.emplace();
#endif
  if (m < kParallelThreshold || team < 2) {
    Eigen::MatrixXd k_block, v_block;
    for (Eigen::Index block = 0; block < blocks; ++block) {
      const Eigen::Index first = block * kQueryBlock;
      evaluate_block(x, first, std::min(kQueryBlock, m - first), what, k_block, v_block, out, out.clamped_variances);
    }
    return;
  }
  long long clamped = 0;
#pragma omp parallel num_threads(team) reduction(+ : clamped)
  {
    Eigen::MatrixXd k_block, v_block;
    // Each block writes disjoint rows of `out`; the clamp counter is per thread.
#pragma omp for schedule(dynamic, 1)
    for (Eigen::Index block = 0; block < blocks; ++block) {
      const Eigen::Index first = block * kQueryBlock;
      evaluate_block(x, first, std::min(kQueryBlock, m - first), what, k_block, v_block, out, clamped);
    }
  }
  out.clamped_variances += clamped;
}

IntervalMeaning GaussianProcess::interval_meaning() const {
  if (state_.interval_of_mean) return IntervalMeaning::mean_over_draws;
  return state_.micro_std_error > 0.0 ? IntervalMeaning::shared_scatter : IntervalMeaning::new_run;
}

void GaussianProcess::attach_patch_scatter(std::shared_ptr<const GaussianProcess> scatter) {
  if (scatter && !same_input_space(scatter->inputs(), inputs())) {
    throw Error("Gaussian process: the patch scatter's inputs or box differ from the model's");
  }
  if (!scatter || scatter->mu_min() == std::numeric_limits<double>::lowest()) {
    patch_scatter_ = std::move(scatter);
    return;
  }
  // Its output is a log variance, not a μ: FrictionModel::evaluate (what its fast evaluator is built
  // and checked from) must not clamp it to μ's range.
  auto log_variance = std::make_shared<GaussianProcess>(*scatter);
  log_variance->set_unbounded_output();
  patch_scatter_ = std::move(log_variance);
}

void GaussianProcess::set_unbounded_output() {
  set_mu_range(std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max());
}

void GaussianProcess::attach_patch_scatter_fast_evaluator(std::shared_ptr<const FastEvaluator> fast) {
  if (!patch_scatter_) throw Error("Gaussian process: a fast evaluator of the patch scatter needs a patch scatter");
  auto scatter = std::make_shared<GaussianProcess>(*patch_scatter_);
  scatter->attach_fast_evaluator(std::move(fast));
  patch_scatter_ = std::move(scatter);
}

Eigen::VectorXd GaussianProcess::patch_std(const QueryBatch& x, double std_relative_tolerance) const {
  if (!patch_scatter_) return {};
  return std_from_log_variance(*patch_scatter_, x, std_relative_tolerance);
}

Eigen::VectorXd GaussianProcess::patch_std_valid(const QueryBatch& x, const EvaluationRequest& what) const {
  // patch_std is a standard deviation: held to σ's relative tolerance.
  return patch_std(x, what.exact_only() ? 0.0 : what.std_relative_tolerance);
}

Eigen::VectorXd GaussianProcess::std_from_log_variance(const GaussianProcess& log_variance, const QueryBatch& x,
                                                       double std_relative_tolerance) {
  // The scatter GP's output is a log variance: not a μ, so not FrictionModel::evaluate's μ range or
  // policies. A point outside the box takes its nearest face's value; a non-finite one none.
  QueryBatch clamped = x;
  std::vector<Eigen::Index> finite_rows;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (!x.row(i).allFinite()) continue;
    finite_rows.push_back(i);
    for (Eigen::Index j = 0; j < x.cols(); ++j) {
      const InputSpec& input = log_variance.inputs()[static_cast<size_t>(j)];
      clamped(i, j) = std::clamp(x(i, j), input.lo, input.hi);
    }
  }
  QueryBatch finite(static_cast<Eigen::Index>(finite_rows.size()), x.cols());
  for (size_t k = 0; k < finite_rows.size(); ++k) finite.row(static_cast<Eigen::Index>(k)) = clamped.row(finite_rows[k]);
  Evaluation e;
  e.mu.resize(finite.rows());
  EvaluationRequest mean_only;
  mean_only.mu_tolerance = patch_scatter_log_variance_tolerance(std_relative_tolerance);  // 0: exact
  mean_only.std_relative_tolerance = 1.0;  // the scatter's own σ is never served
  if (finite.rows() > 0) log_variance.evaluate_valid(finite, mean_only, e);
  Eigen::VectorXd out = Eigen::VectorXd::Constant(x.rows(), std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < finite_rows.size(); ++k) out(finite_rows[k]) = std::exp(0.5 * e.mu(static_cast<Eigen::Index>(k)));
  return out;
}

}  // namespace mufric
