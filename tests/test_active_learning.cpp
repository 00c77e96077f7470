// Greedy posterior-variance selection against brute force: after each pick, the posterior variance
// at every candidate recomputed from scratch with the picks added to the training inputs (dense LU
// of the augmented kernel matrix) must be what the rank-one updates gave, and each pick its argmax.
#include <gtest/gtest.h>

#include <cmath>

#include "gp_test_data.hpp"
#include "surrogate/active_learning.hpp"
#include "surrogate/gp_training.hpp"
#include "surrogate/sampling.hpp"

namespace mufric {
namespace {

Eigen::RowVectorXd unit_row(const InputSpace& in, const Eigen::RowVectorXd& x) {
  Eigen::RowVectorXd u(x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) u(j) = (x(j) - in[static_cast<size_t>(j)].lo) / (in[static_cast<size_t>(j)].hi - in[static_cast<size_t>(j)].lo);
  return u;
}

double kernel(const Eigen::RowVectorXd& a, const Eigen::RowVectorXd& b, const GpHyperParameters& h) {
  return h.signal_variance * std::exp(-0.5 * ((a - b).array() / h.length_scales.transpose().array()).square().sum());
}

// Posterior variance (normalised units, without noise) at q given training rows `x` (unit box).
double brute_force_variance(const Eigen::MatrixXd& x, const Eigen::RowVectorXd& q, const GpHyperParameters& h, double noise) {
  const Eigen::Index n = x.rows();
  Eigen::MatrixXd k(n, n);
  Eigen::VectorXd kq(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    kq(i) = kernel(x.row(i), q, h);
    for (Eigen::Index j = 0; j < n; ++j) k(i, j) = kernel(x.row(i), x.row(j), h) + (i == j ? noise : 0.0);
  }
  return kernel(q, q, h) - kq.dot(k.partialPivLu().solve(kq));
}

TEST(ActiveLearning, GreedyPicksMatchBruteForcePosteriorVariance) {
  const TrainingSet data = test::smooth_training_set(15, 5);
  GpTrainingOptions options;
  options.restarts = 1;
  const GaussianProcess gp = train_gaussian_process(data, options);
  const auto& s = gp.state();
  const Eigen::MatrixXd candidates = plan_in_box(PlanDesign::sobol, 60, s.inputs, 3);
  const auto picks = pick_by_posterior_variance(gp, candidates, 5);
  ASSERT_EQ(picks.size(), 5u);
  const double noise = s.hyper.noise_variance + s.jitter;
  Eigen::MatrixXd x(s.x_train.rows(), s.x_train.cols());
  for (Eigen::Index i = 0; i < x.rows(); ++i) x.row(i) = unit_row(s.inputs, s.x_train.row(i));
  for (const auto& pick : picks) {
    double best = -1.0;
    Eigen::Index best_index = -1;
    for (Eigen::Index c = 0; c < candidates.rows(); ++c) {
      const double var = brute_force_variance(x, unit_row(s.inputs, candidates.row(c)), s.hyper, noise);
      if (var > best) best = var, best_index = c;
    }
    EXPECT_EQ(pick.candidate, best_index);
    EXPECT_NEAR(pick.std_at_pick, s.y_scale * std::sqrt(best), 1e-6 * s.y_scale);
    x.conservativeResize(x.rows() + 1, Eigen::NoChange);
    x.row(x.rows() - 1) = unit_row(s.inputs, candidates.row(pick.candidate));
  }
  // The first pick's std is the model's own predictive std there, minus the noise term.
  Evaluation e = gp.evaluate(candidates.row(picks[0].candidate), {.std = true});
  const double noise_mu = s.y_scale * s.y_scale * s.hyper.noise_variance;
  EXPECT_NEAR(picks[0].std_at_pick, std::sqrt(std::max(e.std(0) * e.std(0) - noise_mu, 0.0)), 1e-6 * s.y_scale);
}

// Failed runs count as observed: with them conditioned on first, the picks are those brute force
// finds with the failed points added to the training inputs.
TEST(ActiveLearning, FailedRunsAreConditionedOnAndNeverPicked) {
  const TrainingSet data = test::smooth_training_set(12, 8);
  GpTrainingOptions options;
  options.restarts = 0;
  const GaussianProcess gp = train_gaussian_process(data, options);
  const auto& s = gp.state();
  const Eigen::MatrixXd candidates = plan_in_box(PlanDesign::sobol, 40, s.inputs, 5);
  const Eigen::MatrixXd tried = plan_in_box(PlanDesign::random, 3, s.inputs, 6);
  const auto picks = pick_by_posterior_variance(gp, candidates, 3, tried);
  Eigen::MatrixXd x(s.x_train.rows() + 3, 3);
  for (Eigen::Index i = 0; i < s.x_train.rows(); ++i) x.row(i) = unit_row(s.inputs, s.x_train.row(i));
  for (Eigen::Index i = 0; i < 3; ++i) x.row(s.x_train.rows() + i) = unit_row(s.inputs, tried.row(i));
  const double noise = s.hyper.noise_variance + s.jitter;
  for (const auto& pick : picks) {
    ASSERT_LT(pick.candidate, candidates.rows());
    Eigen::Index best_index = -1;
    double best = -1.0;
    for (Eigen::Index c = 0; c < candidates.rows(); ++c) {
      const double var = brute_force_variance(x, unit_row(s.inputs, candidates.row(c)), s.hyper, noise);
      if (var > best) best = var, best_index = c;
    }
    EXPECT_EQ(pick.candidate, best_index);
    x.conservativeResize(x.rows() + 1, Eigen::NoChange);
    x.row(x.rows() - 1) = unit_row(s.inputs, candidates.row(pick.candidate));
  }
}

}  // namespace
}  // namespace mufric
