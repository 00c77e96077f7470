#pragma once
// The posterior predictive of a calibration (surrogate/calibration/calibration.hpp): μ at new
// conditions from the posterior's samples, with the parts of its interval.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "surrogate/calibration/calibration.hpp"

namespace mufric {

// The calibrated prediction at conditions (rows, SI), averaged over posterior samples: per sample
// the latent truth ζ = η(x, θ) + δ(x) conditioned on the measurements (KOH eq. 6), then mean and
// variance of the mixture. The parts of its variance, each on its own (they need not add up: given
// y, η and δ are correlated):
struct CalibratedPrediction {
  Eigen::VectorXd mean, sd;
  Eigen::VectorXd discrepancy_mean, discrepancy_sd;  // δ's posterior alone (0 with δ off)
  Eigen::VectorXd parameter_sd;  // the spread of the per-sample means: θ's (and δ's hyper-parameters') share
  Eigen::VectorXd emulator_sd;   // η's own given y: the campaign's interval of the mean over roughness draws
  // √E_s[v_s]: η + δ given y and θ, so that sd² = parameter_sd² + conditional_sd² exactly.
  Eigen::VectorXd conditional_sd;
};

// The posterior predictive of a calibration: per posterior sample (θ, σ_δ, ℓ_δ) the likelihood's
// factor and weights, computed once, so that predictions at new conditions cost a cross-covariance
// and two triangular solves per sample. Safe to call from many threads at once.
class CalibratedPosterior {
 public:
  // `samples`: posterior states in natural units (CalibrationResult::samples' layout); `thinned`
  // evenly spaced rows of them are kept (walker by walker, so every walker contributes). Throws
  // Error when a sample's likelihood covariance is not positive definite.
  CalibratedPosterior(std::shared_ptr<const CalibrationProblem> problem, const Eigen::MatrixXd& samples,
                      Eigen::Index thinned = kDefaultThinnedSamples);
  static constexpr Eigen::Index kDefaultThinnedSamples = 200;

  // In blocks of exactly kPredictionBlockRows conditions (the last one padded with copies of its
  // last row), the samples of a block shared among max_threads threads (0: as many as OpenMP allows;
  // evaluation_team_size). Every product then has the same shapes whatever the batch, so a point's
  // answer is the same bits alone, in any batch and on any team; the memory is bounded too.
  CalibratedPrediction predict(const Eigen::MatrixXd& conditions, int max_threads = 0) const;
  static constexpr Eigen::Index kPredictionBlockRows = 16;
  const CalibrationProblem& problem() const { return *problem_; }
  // The kept samples, one row each (natural units).
  const Eigen::MatrixXd& samples() const { return kept_; }

 private:
  struct Sample {
    PosteriorPoint point;
    CalibrationProblem::Likelihood likelihood;
    Eigen::VectorXd weights;  // (C_η + K_δ + diag s²)⁻¹ (y − m − b)
  };
  // Rows [first, first + count) of out from every kept sample, for the first count rows of a block
  // of kPredictionBlockRows conditions.
  void predict_block(const Eigen::MatrixXd& block, Eigen::Index count, Eigen::Index first, int max_threads,
                     CalibratedPrediction& out) const;

  std::shared_ptr<const CalibrationProblem> problem_;
  Eigen::MatrixXd kept_;
  std::vector<Sample> samples_;
};

// CalibratedPosterior(problem, result.samples, thinned).predict(conditions), for a single use.
CalibratedPrediction predict_calibrated(const CalibrationProblem& problem, const CalibrationResult& result,
                                        const Eigen::MatrixXd& conditions,
                                        Eigen::Index thinned = CalibratedPosterior::kDefaultThinnedSamples);

}  // namespace mufric
