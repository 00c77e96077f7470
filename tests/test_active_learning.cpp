// Greedy posterior-variance selection against brute force: after each pick, the posterior variance
// at every candidate recomputed from scratch with the picks added to the training inputs (dense LU
// of the augmented kernel matrix) must be what the rank-one updates gave, and each pick its argmax.
#include <gtest/gtest.h>

#include <cmath>

#include "gp_test_data.hpp"
#include "surrogate/gp/active_learning.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/core/sampling.hpp"

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

// Posterior variance (normalised units, without noise at q) given training rows `x` (unit box) observed
// with per-point noise variances.
double brute_force_variance(const Eigen::MatrixXd& x, const Eigen::RowVectorXd& q, const GpHyperParameters& h,
                            const Eigen::VectorXd& noise) {
  const Eigen::Index n = x.rows();
  Eigen::MatrixXd k(n, n);
  Eigen::VectorXd kq(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    kq(i) = kernel(x.row(i), q, h);
    for (Eigen::Index j = 0; j < n; ++j) k(i, j) = kernel(x.row(i), x.row(j), h) + (i == j ? noise(i) : 0.0);
  }
  return kernel(q, q, h) - kq.dot(k.fullPivLu().solve(kq));
}

// The same with one noise variance for every point.
double brute_force_variance(const Eigen::MatrixXd& x, const Eigen::RowVectorXd& q, const GpHyperParameters& h, double noise) {
  return brute_force_variance(x, q, h, Eigen::VectorXd::Constant(x.rows(), noise));
}

// Each pick must be the brute-force argmax of the posterior variance given the training inputs,
// `tried` and the earlier picks, with the std brute force gives there.
void expect_brute_force_picks(const GaussianProcess& gp, const Eigen::MatrixXd& candidates,
                              const std::vector<VariancePick>& picks, const Eigen::MatrixXd& tried) {
  const auto& s = gp.state();
  Eigen::MatrixXd x(s.x_train.rows() + tried.rows(), s.x_train.cols());
  for (Eigen::Index i = 0; i < s.x_train.rows(); ++i) x.row(i) = unit_row(s.inputs, s.x_train.row(i));
  for (Eigen::Index i = 0; i < tried.rows(); ++i) x.row(s.x_train.rows() + i) = unit_row(s.inputs, tried.row(i));
  const double noise = s.hyper.noise_variance + s.jitter;
  for (const auto& pick : picks) {
    ASSERT_LT(pick.candidate, candidates.rows());
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
}

GaussianProcess trained_gp(Eigen::Index n, unsigned seed) {
  GpTrainingOptions options;
  options.restarts = 1;
  return train_gaussian_process(test::smooth_training_set(n, seed), options);
}

TEST(ActiveLearning, GreedyPicksMatchBruteForcePosteriorVariance) {
  const GaussianProcess gp = trained_gp(15, 5);
  const auto& s = gp.state();
  const Eigen::MatrixXd candidates = plan_in_box(PlanDesign::sobol, 60, s.inputs, 3);
  const auto picks = pick_by_posterior_variance(gp, candidates, 5);
  ASSERT_EQ(picks.size(), 5u);
  expect_brute_force_picks(gp, candidates, picks, Eigen::MatrixXd(0, 3));
  // The first pick's std is the model's own predictive std there, minus the noise term.
  Evaluation e = gp.evaluate(candidates.row(picks[0].candidate), {.std = true});
  const double noise_mu = s.y_scale * s.y_scale * s.hyper.noise_variance;
  EXPECT_NEAR(picks[0].std_at_pick, std::sqrt(std::max(e.std(0) * e.std(0) - noise_mu, 0.0)), 1e-6 * s.y_scale);
}

// Failed runs count as observed: with them conditioned on first, the picks are those brute force
// finds with the failed points added to the training inputs.
TEST(ActiveLearning, FailedRunsAreConditionedOnAndNeverPicked) {
  const GaussianProcess gp = trained_gp(12, 8);
  const Eigen::MatrixXd candidates = plan_in_box(PlanDesign::sobol, 40, gp.state().inputs, 5);
  const Eigen::MatrixXd tried = plan_in_box(PlanDesign::random, 3, gp.state().inputs, 6);
  const auto picks = pick_by_posterior_variance(gp, candidates, 3, tried);
  ASSERT_EQ(picks.size(), 3u);
  expect_brute_force_picks(gp, candidates, picks, tried);
}

// The IMSE reduction of each pick against brute force: the mean posterior variance over the
// reference points with the earlier picks, less that with this pick too (dense LU with the picks
// appended as noisy observations); each pick the brute-force argmax over the candidates. A GP with
// known per-sample noise (stochastic kriging), candidates of very different noise, two of them at
// training points (replicates).
TEST(ActiveLearning, ImseReductionMatchesBruteForceAndPicksItsArgmax) {
  TrainingSet t = test::smooth_training_set(30, 4);
  t.mu_std.resize(30);
  for (Eigen::Index i = 0; i < 30; ++i) t.mu_std(i) = 0.002 + 0.004 * static_cast<double>(i % 5);
  const GaussianProcess gp = train_gaussian_process(t, test::fixed_stochastic_kriging(1.5, Eigen::Vector3d(0.4, 0.6, 0.5), 1e-4));
  const auto& s = gp.state();
  Eigen::MatrixXd candidates = plan_in_box(PlanDesign::sobol, 40, s.inputs, 3);
  candidates.row(0) = s.x_train.row(2);  // replicates
  candidates.row(1) = s.x_train.row(7);
  Eigen::VectorXd noise(40);
  for (Eigen::Index i = 0; i < 40; ++i) noise(i) = std::pow(0.001 + 0.01 * static_cast<double>(i % 4), 2);
  const Eigen::MatrixXd reference = plan_in_box(PlanDesign::sobol, 64, s.inputs, 9);
  const auto picks = pick_by_imse_reduction(gp, candidates, noise, reference, 4);
  ASSERT_EQ(picks.size(), 4u);

  // The training rows in the unit box with their total diagonal noise, normalised.
  Eigen::MatrixXd x = to_unit_box(s.x_train, s.inputs);
  Eigen::VectorXd diagonal = s.known_noise.array() + s.hyper.noise_variance + s.jitter;
  const double scale2 = s.y_scale * s.y_scale;
  auto mean_variance = [&](const Eigen::MatrixXd& rows, const Eigen::VectorXd& d) {
    double sum = 0.0;
    for (Eigen::Index r = 0; r < reference.rows(); ++r) {
      sum += brute_force_variance(rows, unit_row(s.inputs, reference.row(r)), s.hyper, d);
    }
    return sum / static_cast<double>(reference.rows());
  };
  auto with = [](const Eigen::MatrixXd& rows, const Eigen::RowVectorXd& row) {
    Eigen::MatrixXd out(rows.rows() + 1, rows.cols());
    out << rows, row;
    return out;
  };
  auto with_value = [](const Eigen::VectorXd& v, double value) {
    Eigen::VectorXd out(v.size() + 1);
    out << v, value;
    return out;
  };
  std::vector<bool> taken(40, false);
  for (const auto& pick : picks) {
    const double before = mean_variance(x, diagonal);
    double best = -1.0;
    Eigen::Index argmax = -1;
    for (Eigen::Index c = 0; c < 40; ++c) {
      if (taken[static_cast<size_t>(c)]) continue;
      const double gain = before - mean_variance(with(x, unit_row(s.inputs, candidates.row(c))), with_value(diagonal, noise(c) / scale2));
      if (gain > best) {
        best = gain;
        argmax = c;
      }
    }
    EXPECT_EQ(pick.candidate, argmax);
    EXPECT_NEAR(pick.imse_reduction, best * scale2, 1e-8 * best * scale2);
    taken[static_cast<size_t>(pick.candidate)] = true;
    x = with(x, unit_row(s.inputs, candidates.row(pick.candidate)));
    diagonal = with_value(diagonal, noise(pick.candidate) / scale2);
  }
}

}  // namespace
}  // namespace mufric
