#include "surrogate/calibration/calibrated_posterior.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "common/blas_threads.hpp"
#include "common/error.hpp"

namespace mufric {

CalibratedPosterior::CalibratedPosterior(std::shared_ptr<const CalibrationProblem> problem, const Eigen::MatrixXd& samples,
                                         Eigen::Index thinned)
    : problem_(std::move(problem)) {
  const Eigen::Index total = samples.rows();
  if (total < 1) throw Error("calibrated prediction: no posterior samples");
  if (samples.cols() != problem_->dimension()) {
    throw Error("calibrated prediction: posterior samples have " + std::to_string(samples.cols()) + " coordinates for " +
                std::to_string(problem_->dimension()));
  }
  const Eigen::Index used = std::max<Eigen::Index>(1, std::min(thinned, total));
  kept_.resize(used, samples.cols());
  for (Eigen::Index s = 0; s < used; ++s) {
    // Evenly spaced through the pooled samples (walker by walker), so every walker contributes.
    kept_.row(s) = samples.row(s * total / used);
    Sample sample;
    sample.point = problem_->point_at(kept_.row(s).transpose());
    sample.likelihood = problem_->likelihood_at(sample.point);
    if (sample.likelihood.factor.info() != Eigen::Success) {
      throw Error("calibrated prediction: the likelihood's covariance at posterior sample " + std::to_string(s) +
                  " is not positive definite");
    }
    sample.weights = sample.likelihood.factor.solve(sample.likelihood.residual);
    samples_.push_back(std::move(sample));
  }
}

CalibratedPrediction CalibratedPosterior::predict(const Eigen::MatrixXd& conditions, int max_threads) const {
  const Eigen::Index q = conditions.rows();
  CalibratedPrediction out;
  for (Eigen::VectorXd* v : {&out.mean, &out.sd, &out.discrepancy_mean, &out.discrepancy_sd, &out.parameter_sd,
                             &out.emulator_sd, &out.conditional_sd}) {
    v->resize(q);
  }
  Eigen::MatrixXd block(kPredictionBlockRows, conditions.cols());
  // The samples' threads are the parallelism: each block's whitening runs on its own thread.
  const SingleThreadedBlas one_blas_thread;
  for (Eigen::Index first = 0; first < q; first += kPredictionBlockRows) {
    const Eigen::Index count = std::min(kPredictionBlockRows, q - first);
    block.topRows(count) = conditions.middleRows(first, count);
    for (Eigen::Index r = count; r < kPredictionBlockRows; ++r) block.row(r) = conditions.row(first + count - 1);
    predict_block(block, count, first, max_threads, out);
  }
  return out;
}

void CalibratedPosterior::predict_block(const Eigen::MatrixXd& conditions, Eigen::Index count, Eigen::Index first,
                                        int max_threads, CalibratedPrediction& out) const {
  const CalibrationProblem& problem = *problem_;
  const GaussianProcess& emulator = problem.emulator();
  const Eigen::Index q = conditions.rows(), used = static_cast<Eigen::Index>(samples_.size());
  if (q != kPredictionBlockRows) throw Error("calibrated prediction: a block of " + std::to_string(q) + " rows");
  const Eigen::MatrixXd unit_new = problem.discrepancy() ? problem.unit_conditions(conditions) : Eigen::MatrixXd();
  Eigen::MatrixXd means(q, used), variances(q, used), discrepancy_means(q, used), discrepancy_variances(q, used),
      emulator_variances(q, used);
  const double trend_sd = problem.priors().discrepancy_trend_sd;
  auto predict_sample = [&](Eigen::Index s, const GaussianProcess::LatentPoints& at) {
    const Sample& sample = samples_[static_cast<size_t>(s)];
    const auto lower = sample.likelihood.factor.matrixL();
    // ζ(x) = η(x, θ) + δ(x) given y (KOH eq. 6): cov(η(x), y) = C_η(x, X), cov(δ(x), y) = K_δ(x, X).
    // diag(A C⁻¹ Aᵀ) = |L⁻¹Aᵀ|² per column, with C = LLᵀ the likelihood's factor.
    const Eigen::MatrixXd emulator_cross = emulator.latent_covariance(at, sample.likelihood.measured);
    const Eigen::MatrixXd emulator_explained = lower.solve(emulator_cross.transpose());
    const Eigen::VectorXd prior_emulator_variance = emulator.latent_variance(at);
    emulator_variances.col(s) = prior_emulator_variance - emulator_explained.colwise().squaredNorm().transpose();
    if (problem.discrepancy()) {
      const Eigen::MatrixXd discrepancy_cross =
          CalibrationProblem::discrepancy_covariance(unit_new, sample.likelihood.unit_conditions, sample.point.amplitude,
                                                     sample.point.length_scale, trend_sd);
      const Eigen::VectorXd discrepancy_variance =
          CalibrationProblem::discrepancy_variance(unit_new, sample.point.amplitude, trend_sd);
      const Eigen::MatrixXd discrepancy_explained = lower.solve(discrepancy_cross.transpose());
      discrepancy_means.col(s) = discrepancy_cross * sample.weights;
      discrepancy_variances.col(s) =
          discrepancy_variance - discrepancy_explained.colwise().squaredNorm().transpose();
      means.col(s) = at.mean + emulator_cross * sample.weights + discrepancy_means.col(s);
      variances.col(s) = prior_emulator_variance.array() + discrepancy_variance.array() -
                         (emulator_explained + discrepancy_explained).colwise().squaredNorm().transpose().array();
    } else {
      discrepancy_means.col(s).setZero();
      discrepancy_variances.col(s).setZero();
      means.col(s) = at.mean + emulator_cross * sample.weights;
      variances.col(s) = emulator_variances.col(s);
    }
  };
  // The emulator's points of kSamplesPerWhitening samples are whitened together, one full block of
  // the GP's batch product (2.6× Eigen's SSE2 product in a portable build; bench/studies/ti6al4v/README.md); the
  // last group is padded with copies of the last sample, so every block has the same shape and a
  // sample's bits do not depend on how many were kept. Each sample writes its own columns: the
  // threads share nothing but what they read.
  static_assert(kEvaluationBlockRows % kPredictionBlockRows == 0);
  constexpr Eigen::Index kSamplesPerWhitening = kEvaluationBlockRows / kPredictionBlockRows;
  const Eigen::Index groups = (used + kSamplesPerWhitening - 1) / kSamplesPerWhitening;
  auto predict_group = [&](Eigen::Index group) {
    Eigen::MatrixXd stacked;
    for (Eigen::Index j = 0; j < kSamplesPerWhitening; ++j) {
      const Eigen::Index s = std::min(group * kSamplesPerWhitening + j, used - 1);
      const Eigen::MatrixXd points = problem.emulator_points(conditions, samples_[static_cast<size_t>(s)].point.theta);
      if (j == 0) stacked.resize(kEvaluationBlockRows, points.cols());
      stacked.middleRows(j * q, q) = points;
    }
    const GaussianProcess::LatentPoints all = emulator.latent_points(stacked);
    for (Eigen::Index j = 0; j < kSamplesPerWhitening && group * kSamplesPerWhitening + j < used; ++j) {
      predict_sample(group * kSamplesPerWhitening + j, all.rows(j * q, q));
    }
  };
  const int team = evaluation_team_size(max_threads);
#pragma omp parallel for num_threads(team) schedule(static) if (team > 1)
  for (Eigen::Index group = 0; group < groups; ++group) predict_group(group);

  // A mixture's moments: the mean of the means; the mean variance plus the variance of the means.
  auto spread = [used](const Eigen::MatrixXd& m) {
    const Eigen::VectorXd centre = m.rowwise().mean();
    return Eigen::VectorXd(((m.colwise() - centre).array().square().rowwise().sum() / static_cast<double>(used)).matrix());
  };
  const Eigen::VectorXd between = spread(means);
  const Eigen::VectorXd within = variances.rowwise().mean().cwiseMax(0.0);
  out.mean.segment(first, count) = means.rowwise().mean().head(count);
  out.parameter_sd.segment(first, count) = between.cwiseSqrt().head(count);
  out.sd.segment(first, count) = (within + between).cwiseSqrt().head(count);
  out.conditional_sd.segment(first, count) = within.cwiseSqrt().head(count);
  out.emulator_sd.segment(first, count) = emulator_variances.rowwise().mean().cwiseMax(0.0).cwiseSqrt().head(count);
  out.discrepancy_mean.segment(first, count) = discrepancy_means.rowwise().mean().head(count);
  out.discrepancy_sd.segment(first, count) =
      (discrepancy_variances.rowwise().mean().cwiseMax(0.0) + spread(discrepancy_means)).cwiseSqrt().head(count);
}

CalibratedPrediction predict_calibrated(const CalibrationProblem& problem, const CalibrationResult& result,
                                        const Eigen::MatrixXd& conditions, Eigen::Index thinned) {
  // Not owned: the posterior lives only for this call.
  const std::shared_ptr<const CalibrationProblem> borrowed(&problem, [](const CalibrationProblem*) {});
  return CalibratedPosterior(borrowed, result.samples, thinned).predict(conditions);
}

}  // namespace mufric
