#pragma once
// Stochastic kriging of a campaign of independent draws (issue 33): the GP learns μ averaged over all
// draws of the roughness statistics, each sample's own variance of its mean on the covariance
// diagonal (Ankenman, Nelson & Staum 2010, Oper. Res. 58(2):371, eq. 6), so that its interval
// shrinks as the campaign grows. With a few draws per sample, a sample variance is itself uncertain
// by a factor of 2–3 (four draws: the standard deviation of log s² is 0.97), so the diagonal holds
// a smoothed one: a second GP of log s² over the inputs (the patch scatter; hetGP's idea, Binois,
// Gramacy & Ludkovski 2018, J. Comput. Graph. Stat. 27(4):808), with each log s²'s known sampling
// variance on its own diagonal. That GP is also served on its own: how much one contact patch's μ
// scatters about the mean.
#include <vector>

#include <Eigen/Dense>

#include "common/dataset_file.hpp"
#include "surrogate/gp/gaussian_process.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {

// Each training sample's count of finite draws (its row of draw_mu; 0 without per-draw μ).
Eigen::VectorXi finite_draws(const TrainingSet& data);

// Per-sample log variances of the draws, for samples with at least two finite draws.
struct DrawVariances {
  std::vector<Eigen::Index> rows;          // rows of the training set
  Eigen::VectorXd log_variance;            // unbiased for log σ²(x): log s² − ψ(k) + log k, k = (r − 1)/2
  Eigen::VectorXd log_variance_variance;   // its sampling variance ψ′(k)
  Eigen::VectorXi draws;                   // r
};
// For normal draws (r − 1)s²/σ² is χ² with r − 1 degrees of freedom, so log s² has mean
// log σ² + ψ(k) − log k and variance ψ′(k) (Bartlett & Kendall 1946, JRSS Suppl. 8(2):128).
DrawVariances draw_variances(const TrainingSet& data);

struct StochasticKrigingReport {
  GpTrainingReport scatter, mean;
  long long scatter_samples = 0;        // samples with ≥ 2 draws, the patch scatter's data
  // Fewer than two such samples: no patch scatter; the mean's GP learns one noise level, the per-draw
  // variance, and serves the mean's interval without it.
  bool homoscedastic = false;
  long long draws = 0;                  // finite draws in all samples
  double median_patch_std = 0.0;        // the patch scatter at the training points, μ units
  double median_sample_std_error = 0.0; // the smoothed standard error of a sample's mean there
};

// The patch scatter, then the mean. Throws Error naming the sample when one has no draws. With
// fewer than two samples of two draws or more (one draw per sample), the mean alone (homoscedastic).
GaussianProcess train_stochastic_kriging(const TrainingSet& data, const GpTrainingOptions& options,
                                         StochasticKrigingReport* report = nullptr);

// Whether a training set is one stochastic kriging is for: independent draws, each sample's μ per draw.
bool suits_stochastic_kriging(const TrainingSet& data);

}  // namespace mufric
