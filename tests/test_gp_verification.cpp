// The GP against independent answers: dense LU formulas, finite differences, brute-force search
// and brute-force leave-one-out.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "gp_test_data.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {
namespace {

GpTrainingOptions fixed(double s2, Eigen::VectorXd lengths, double noise) {
  GpTrainingOptions o;
  o.optimise = false;
  o.initial.signal_variance = s2;
  o.initial.length_scales = std::move(lengths);
  o.initial.noise_variance = noise;
  o.noise_term = noise > 0.0;
  return o;
}

// K computed element by element with the textbook formula, no shared code with the library.
Eigen::MatrixXd dense_covariance(const Eigen::MatrixXd& u, const GpHyperParameters& h, double diagonal) {
  const Eigen::Index n = u.rows();
  Eigen::MatrixXd k(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      double r2 = 0.0;
      for (Eigen::Index c = 0; c < u.cols(); ++c) r2 += std::pow((u(i, c) - u(j, c)) / h.length_scales(c), 2);
      k(i, j) = h.signal_variance * std::exp(-0.5 * r2) + (i == j ? diagonal : 0.0);
    }
  }
  return k;
}

// σ² exp(−½ Σ ((q − xᵢ)/l)²) for every training row xᵢ of u.
Eigen::VectorXd dense_kernel_vector(const Eigen::RowVectorXd& q, const Eigen::MatrixXd& u, const Eigen::VectorXd& lengths,
                                    double s2) {
  Eigen::VectorXd k(u.rows());
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    k(i) = s2 * std::exp(-0.5 * ((q - u.row(i)).array() / lengths.transpose().array()).square().sum());
  }
  return k;
}

double dense_lml(const Eigen::MatrixXd& u, const Eigen::VectorXd& y, const GpHyperParameters& h) {
  const Eigen::MatrixXd k = dense_covariance(u, h, h.noise_variance);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(k);
  const double log_det = lu.matrixLU().diagonal().array().abs().log().sum();
  return -0.5 * y.dot(lu.solve(y)) - 0.5 * log_det - 0.5 * static_cast<double>(y.size()) * std::log(2 * std::numbers::pi);
}

TEST(GpVerification, LogMarginalLikelihoodMatchesDenseLuFormula) {
  const TrainingSet data = test::smooth_training_set(40, 3);
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::VectorXd y = (data.mu.array() - data.mu.mean()) / 0.05;
  for (const bool noise : {true, false}) {
    LogMarginalLikelihood lml(u, y, noise);
    GpHyperParameters h;
    h.signal_variance = 2.5;
    h.length_scales = Eigen::Vector3d(0.7, 0.4, 1.3);
    h.noise_variance = noise ? 1e-3 : 0.0;
    h.noise_term = noise;
    const auto value = lml(h.to_log(), false);
    ASSERT_TRUE(value.ok) << value.reason;
    EXPECT_EQ(value.jitter, 0.0);
    EXPECT_NEAR(value.lml, dense_lml(u, y, h), 1e-8 * std::abs(value.lml));
  }
}

// The restricted likelihood against its definition: the density of n − 1 orthonormal contrasts Ay
// (A1 = 0, AAᵀ = I), which is REML's up to −½ log n (Harville 1974, Biometrika 61(2):383).
TEST(GpVerification, RestrictedLikelihoodIsTheDensityOfTheContrasts) {
  const TrainingSet data = test::smooth_training_set(30, 6);
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::VectorXd y = (data.mu.array() - 0.3) / 0.05;  // any offset: REML does not see it
  const Eigen::Index n = y.size();
  const Eigen::VectorXd known = Eigen::VectorXd::LinSpaced(n, 1e-3, 5e-2);
  LogMarginalLikelihood reml(u, y, true, known, true);
  GpHyperParameters h;
  h.signal_variance = 1.8;
  h.length_scales = Eigen::Vector3d(0.6, 0.5, 1.1);
  h.noise_variance = 2e-3;
  h.noise_term = true;
  const auto value = reml(h.to_log(), false);
  ASSERT_TRUE(value.ok) << value.reason;
  // A: the last n − 1 columns of the Q of [1 | I], transposed.
  Eigen::MatrixXd ones_first(n, n);
  ones_first.col(0).setOnes();
  ones_first.rightCols(n - 1) = Eigen::MatrixXd::Identity(n, n).leftCols(n - 1);
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(ones_first).householderQ();
  const Eigen::MatrixXd a = q.rightCols(n - 1).transpose();
  ASSERT_LT((a * Eigen::VectorXd::Ones(n)).norm(), 1e-12);
  Eigen::MatrixXd k = dense_covariance(u, h, h.noise_variance);
  k.diagonal() += known;
  const Eigen::MatrixXd contrast_covariance = a * k * a.transpose();
  const Eigen::VectorXd contrasts = a * y;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(contrast_covariance);
  const double log_det = lu.matrixLU().diagonal().array().abs().log().sum();
  const double density = -0.5 * contrasts.dot(lu.solve(contrasts)) - 0.5 * log_det -
                         0.5 * static_cast<double>(n - 1) * std::log(2 * std::numbers::pi);
  EXPECT_NEAR(value.lml, density - 0.5 * std::log(static_cast<double>(n)), 1e-9 * std::abs(value.lml));
  // Its gradient against central differences.
  const auto with_gradient = reml(h.to_log(), true);
  const Eigen::VectorXd theta = h.to_log();
  constexpr double step = 1e-5;
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    Eigen::VectorXd plus = theta, minus = theta;
    plus(i) += step;
    minus(i) -= step;
    const double fd = (reml(plus, false).lml - reml(minus, false).lml) / (2 * step);
    EXPECT_NEAR(with_gradient.gradient(i), fd, 1e-6 * std::max(1.0, std::abs(fd))) << "parameter " << i;
  }
}

TEST(GpVerification, GradientMatchesCentralFiniteDifferences) {
  const TrainingSet data = test::smooth_training_set(35, 5);
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::VectorXd y = (data.mu.array() - data.mu.mean()) / 0.05;
  LogMarginalLikelihood lml(u, y, true);
  const Eigen::VectorXd theta = (Eigen::VectorXd(5) << std::log(1.7), std::log(0.6), std::log(0.9), std::log(0.5),
                                 std::log(2e-3)).finished();
  const auto value = lml(theta, true);
  ASSERT_TRUE(value.ok);
  constexpr double step = 1e-5;
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    Eigen::VectorXd plus = theta, minus = theta;
    plus(i) += step;
    minus(i) -= step;
    const double fd = (lml(plus, false).lml - lml(minus, false).lml) / (2 * step);
    EXPECT_NEAR(value.gradient(i), fd, 1e-6 * std::max(1.0, std::abs(fd))) << "parameter " << i;
  }
}

// Mean and std of `gp` at 25 queries against the textbook posterior (R&W eq. 2.25–2.26) with a dense
// inverse of the full covariance k; prior_variance is the query's own variance before conditioning.
void expect_dense_posterior(const GaussianProcess& gp, const TrainingSet& data, const Eigen::MatrixXd& k,
                            const Eigen::Vector3d& lengths, double prior_variance, unsigned seed, double mean_tolerance,
                            double std_tolerance, double ci_level) {
  const auto& s = gp.state();
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::MatrixXd k_inv = k.fullPivLu().inverse();
  const Eigen::VectorXd y = (data.mu.array() - s.y_mean) / s.y_scale;
  const TrainingSet queries = test::smooth_training_set(25, seed);
  const Evaluation e = gp.evaluate(queries.x, {.std = true, .ci_level = ci_level, .gradient = false});
  const Eigen::MatrixXd uq = to_unit_box(queries.x, data.inputs);
  for (Eigen::Index q = 0; q < uq.rows(); ++q) {
    const Eigen::VectorXd kq = dense_kernel_vector(uq.row(q), u, lengths, s.hyper.signal_variance);
    EXPECT_NEAR(e.mu(q), s.y_mean + s.y_scale * kq.dot(k_inv * y), mean_tolerance);
    EXPECT_NEAR(e.std(q), s.y_scale * std::sqrt(prior_variance - kq.dot(k_inv * kq)), std_tolerance);
  }
}

TEST(GpVerification, PredictionMatchesDenseFormulaWithExplicitInverse) {
  const TrainingSet data = test::smooth_training_set(40, 11);
  const Eigen::Vector3d lengths(0.8, 0.5, 0.9);
  const GaussianProcess gp = train_gaussian_process(data, fixed(3.0, lengths, 1e-4));
  const auto& s = gp.state();
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::MatrixXd k = dense_covariance(u, s.hyper, s.hyper.noise_variance + s.jitter);
  expect_dense_posterior(gp, data, k, lengths, 3.0 + 1e-4, 99, 1e-9, 1e-8, 0.9);
  const TrainingSet queries = test::smooth_training_set(25, 99);
  const Evaluation e = gp.evaluate(queries.x, {.std = true, .ci_level = 0.9, .gradient = false});
  const double z90 = 1.6448536269514722;
  for (Eigen::Index q = 0; q < e.mu.size(); ++q) EXPECT_NEAR(e.hi(q) - e.lo(q), 2 * z90 * e.std(q), 1e-12);
}

// Known per-sample noise (R&W eq. 2.20 with diag(s_i²) added to K, scikit-learn's `alpha` array) and
// the micro-model's scatter in the interval, against the textbook posterior with a dense inverse.
TEST(GpVerification, KnownPerSampleNoiseMatchesDensePosterior) {
  TrainingSet data = test::smooth_training_set(40, 13);
  data.mu_std.resize(data.mu.size());
  for (Eigen::Index i = 0; i < data.mu_std.size(); ++i) data.mu_std(i) = 1e-3 * (1.0 + 0.05 * static_cast<double>(i % 7));
  const Eigen::Vector3d lengths(0.7, 0.6, 0.9);
  GpTrainingOptions options = fixed(2.0, lengths, 1e-4);
  options.sample_noise = true;
  const GaussianProcess gp = train_gaussian_process(data, options);
  const auto& s = gp.state();
  ASSERT_EQ(s.known_noise.size(), data.mu.size());
  const double micro = std::sqrt(data.mu_std.array().square().mean());
  EXPECT_NEAR(s.micro_std_error, micro, 1e-15);
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  Eigen::MatrixXd k = dense_covariance(u, s.hyper, s.hyper.noise_variance + s.jitter);
  for (Eigen::Index i = 0; i < k.rows(); ++i) k(i, i) += std::pow(data.mu_std(i) / s.y_scale, 2);
  const Eigen::VectorXd y = (data.mu.array() - s.y_mean) / s.y_scale;
  // The LML with the known noise, too.
  LogMarginalLikelihood lml(u, y, true, s.known_noise);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(k);
  const double dense = -0.5 * y.dot(lu.solve(y)) - 0.5 * lu.matrixLU().diagonal().array().abs().log().sum() -
                       0.5 * static_cast<double>(y.size()) * std::log(2 * std::numbers::pi);
  EXPECT_NEAR(lml(s.hyper.to_log(), false).lml, dense, 1e-8 * std::abs(dense));

  expect_dense_posterior(gp, data, k, lengths, 2.0 + 1e-4 + std::pow(micro / s.y_scale, 2), 98, 1e-10, 1e-10, 0.95);
  // Without --sample-noise the diagonal carries only the learned noise, and the scatter stays in std.
  const GaussianProcess plain = train_gaussian_process(data, fixed(2.0, lengths, 1e-4));
  EXPECT_EQ(plain.state().known_noise.size(), 0);
  EXPECT_NEAR(plain.state().micro_std_error, micro, 1e-15);
}

TEST(GpVerification, MeanGradientMatchesFiniteDifferences) {
  const TrainingSet data = test::smooth_training_set(50, 21);
  const GaussianProcess gp = train_gaussian_process(data, fixed(2.0, Eigen::Vector3d(0.6, 0.7, 0.8), 1e-5));
  const TrainingSet queries = test::smooth_training_set(8, 77);
  const Evaluation e = gp.evaluate(queries.x, {.std = false, .ci_level = 0.0, .gradient = true});
  for (Eigen::Index q = 0; q < queries.x.rows(); ++q) {
    for (Eigen::Index c = 0; c < 3; ++c) {
      const auto& in = data.inputs[static_cast<size_t>(c)];
      const double h = 1e-6 * (in.hi - in.lo);
      QueryBatch plus = queries.x.row(q), minus = queries.x.row(q);
      plus(0, c) += h;
      minus(0, c) -= h;
      const double fd = (gp.evaluate(plus, {}).mu(0) - gp.evaluate(minus, {}).mu(0)) / (2 * h);
      EXPECT_NEAR(e.gradient(q, c), fd, 1e-6 * std::abs(fd) + 1e-9 / (in.hi - in.lo)) << "point " << q << " input " << c;
    }
  }
}

TEST(GpVerification, OptimiserBeatsBruteForceGridSearch) {
  // Two hyper-parameters (σ², one length scale) on a 1-D problem: a 80 × 80 grid over the bounds
  // is an independent answer the optimiser must match or beat.
  TrainingSet data;
  data.inputs = {{"x", "1", 0.0, 1.0}};
  const Eigen::Index n = 25;
  data.x.resize(n, 1);
  data.mu.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    data.x(i, 0) = static_cast<double>(i) / static_cast<double>(n - 1);
    data.mu(i) = std::sin(5.0 * data.x(i, 0)) + 0.3 * data.x(i, 0);
  }
  GpTrainingOptions options;
  options.noise_term = false;
  options.restarts = 3;
  GpTrainingReport report;
  const GaussianProcess gp = train_gaussian_process(data, options, &report);
  const double optimised = gp.state().summary.log_marginal_likelihood;

  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::VectorXd y = (data.mu.array() - gp.state().y_mean) / gp.state().y_scale;
  LogMarginalLikelihood lml(u, y, false);
  double best_grid = -1e300;
  for (int a = 0; a < 80; ++a) {
    for (int b = 0; b < 80; ++b) {
      const double log_s2 = std::log(1e-3) + (std::log(1e5) - std::log(1e-3)) * a / 79.0;
      const double log_l = std::log(1e-2) + (std::log(1e3) - std::log(1e-2)) * b / 79.0;
      const auto value = lml(Eigen::Vector2d(log_s2, log_l), false);
      if (value.ok && value.jitter == 0.0) best_grid = std::max(best_grid, value.lml);
    }
  }
  EXPECT_GE(optimised, best_grid - 1e-6);
}

TEST(GpVerification, SubsetStageFindsTheSameOptimumAsPlainMultiStart) {
  // The subset stage, shared basins and not refining hopeless starts only make the search cheaper:
  // the best LML must match plain full-data L-BFGS from the same starts.
  TrainingSet data = test::smooth_training_set(700, 13);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 5e-4);
  for (Eigen::Index i = 0; i < data.mu.size(); ++i) data.mu(i) += noise(rng);
  GpTrainingOptions options;
  options.restarts = 3;
  GpTrainingReport fast_report, plain_report;
  const GaussianProcess fast = train_gaussian_process(data, options, &fast_report);
  options.subset_size = 0;
  const GaussianProcess plain = train_gaussian_process(data, options, &plain_report);
  EXPECT_NEAR(fast.state().summary.log_marginal_likelihood, plain.state().summary.log_marginal_likelihood, 1e-3);
  int full_evaluations_fast = 0, full_evaluations_plain = 0;
  for (const auto& s : fast_report.starts) {
    full_evaluations_fast += s.evaluations;
    EXPECT_GT(s.subset_evaluations, 0);
    EXPECT_LE(s.log_marginal_likelihood, fast.state().summary.log_marginal_likelihood);
  }
  for (const auto& s : plain_report.starts) full_evaluations_plain += s.evaluations;
  EXPECT_LT(full_evaluations_fast, full_evaluations_plain);
}

TEST(GpVerification, ClosedFormLeaveOneOutEqualsBruteForceRefits) {
  const TrainingSet data = test::smooth_training_set(30, 8);
  const Eigen::Vector3d lengths(0.5, 0.6, 0.7);
  const GaussianProcess gp = train_gaussian_process(data, fixed(1.5, lengths, 1e-4));
  double brute_sum = 0.0;
  for (Eigen::Index i = 0; i < 30; ++i) {
    TrainingSet rest = data;
    rest.x.resize(29, 3);
    rest.mu.resize(29);
    for (Eigen::Index r = 0, k = 0; r < 30; ++r) {
      if (r == i) continue;
      rest.x.row(k) = data.x.row(r);
      rest.mu(k++) = data.mu(r);
    }
    // Same normalisation as the full model, so the prior is identical.
    GaussianProcess::State s = gp.state();
    const Eigen::MatrixXd u = to_unit_box(rest.x, data.inputs);
    const Eigen::MatrixXd k = dense_covariance(u, s.hyper, s.hyper.noise_variance);
    const Eigen::VectorXd y = (rest.mu.array() - s.y_mean) / s.y_scale;
    const Eigen::MatrixXd ui = to_unit_box(data.x.row(i), data.inputs);
    const Eigen::VectorXd kq = dense_kernel_vector(ui.row(0), u, lengths, 1.5);
    const double prediction = s.y_mean + s.y_scale * kq.dot(k.ldlt().solve(y));
    brute_sum += std::abs(prediction - data.mu(i)) / std::abs(data.mu(i));
  }
  EXPECT_NEAR(gp.state().summary.loo_mean_relative_error, brute_sum / 30.0, 1e-9);
}

TEST(GpVerification, BatchedParallelEqualsPointByPoint) {
  const TrainingSet data = test::smooth_training_set(120, 4);
  const GaussianProcess gp = train_gaussian_process(data, fixed(2.0, Eigen::Vector3d(0.5, 0.5, 0.5), 1e-4));
  const TrainingSet queries = test::smooth_training_set(1000, 12);
  const EvaluationRequest what{.std = true, .ci_level = 0.95, .gradient = true};
  const Evaluation batch = gp.evaluate(queries.x, what);
  for (Eigen::Index q = 0; q < 1000; q += 37) {
    const Evaluation one = gp.evaluate(queries.x.row(q), what);
    EXPECT_EQ(batch.mu(q), one.mu(0));  // one summation order for μ (MuIsTheSameBitsWhateverElseIsAsked)
    // One point reads L⁻¹ row by row, a batch multiplies by it blockwise: same maths, other rounding.
    EXPECT_NEAR(batch.std(q), one.std(0), 1e-10 * one.std(0));
    // The gradient sums α_i ∂k_i/∂x with cancellation: an ulp in a kernel value (a vector exp lane)
    // moves it by up to 1.2e-12 of |g| (measured); 1e-11 still catches a wrong term.
    EXPECT_NEAR((batch.gradient.row(q) - one.gradient.row(0)).norm(), 0.0, 1e-11 * one.gradient.norm());
  }
}

// An explicit meso run and its twin that also asks for the interval (or the gradient) must get the
// same μ to the last bit, in any batch: the same point alone, in a block, in a parallel batch. n = 121
// makes the kernel block's columns start at every alignment; the matrix–vector product it replaced moved μ in its last bits.
TEST(GpVerification, MuIsTheSameBitsWhateverElseIsAsked) {
  const TrainingSet data = test::smooth_training_set(121, 4);
  const GaussianProcess gp = train_gaussian_process(data, fixed(2.0, Eigen::Vector3d(0.5, 0.5, 0.5), 1e-4));
  const TrainingSet queries = test::smooth_training_set(1000, 12);
  const Evaluation mean_only = gp.evaluate(queries.x, {});
  const std::vector<EvaluationRequest> requests{{.std = true},
                                                {.ci_level = 0.95},
                                                {.gradient = true},
                                                {.std = true, .ci_level = 0.95, .gradient = true}};
  for (const EvaluationRequest& what : requests) {
    for (const Eigen::Index count : {Eigen::Index{1000}, Eigen::Index{200}, Eigen::Index{7}}) {
      const Evaluation e = gp.evaluate(queries.x.topRows(count), what);
      for (Eigen::Index q = 0; q < count; ++q) {
        ASSERT_EQ(e.mu(q), mean_only.mu(q)) << "query " << q << " of " << count;
      }
    }
    for (Eigen::Index q = 0; q < 1000; q += 97) {
      EXPECT_EQ(gp.evaluate(queries.x.row(q), what).mu(0), mean_only.mu(q)) << q;
      EXPECT_EQ(gp.evaluate(queries.x.row(q), {}).mu(0), mean_only.mu(q)) << q;
    }
  }
}

TEST(GpVerification, AllVariancePathsAgreeWithTheDenseFormula) {
  // n = 500: one query splits L⁻¹'s rows over two threads; 2–16 queries read rows once for all;
  // larger batches use a blocked triangular product. All three against Σ = K** − k*ᵀK⁻¹k*.
  const TrainingSet data = test::smooth_training_set(500, 6);
  const Eigen::Vector3d lengths(0.6, 0.8, 0.7);
  const GaussianProcess gp = train_gaussian_process(data, fixed(2.0, lengths, 1e-4));
  const auto& s = gp.state();
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  // Eigen's LLT solve (not LAPACK, not an explicit inverse) as the backward-stable reference.
  const Eigen::LLT<Eigen::MatrixXd> k_llt(dense_covariance(u, s.hyper, s.hyper.noise_variance + s.jitter));
  const TrainingSet queries = test::smooth_training_set(40, 31);
  const Eigen::MatrixXd uq = to_unit_box(queries.x, data.inputs);
  Eigen::VectorXd expected(40);
  for (Eigen::Index q = 0; q < 40; ++q) {
    const Eigen::VectorXd kq = dense_kernel_vector(uq.row(q), u, lengths, 2.0);
    expected(q) = s.y_scale * std::sqrt(2.0 + 1e-4 - kq.dot(k_llt.solve(kq)));
  }
  const Evaluation blocked = gp.evaluate(queries.x, {.std = true});
  const Evaluation few = gp.evaluate(queries.x.topRows(7), {.std = true});
  for (Eigen::Index q = 0; q < 40; ++q) {
    EXPECT_NEAR(blocked.std(q), expected(q), 1e-7 * expected(q)) << q;
    const Evaluation one = gp.evaluate(queries.x.row(q), {.std = true});
    EXPECT_NEAR(one.std(0), blocked.std(q), 1e-10 * expected(q)) << q;
    if (q < 7) {
      EXPECT_NEAR(few.std(q), blocked.std(q), 1e-10 * expected(q)) << q;
    }
  }
}

TEST(GpVerification, MeanOnlyRequestComputesNoVariance) {
  const TrainingSet data = test::smooth_training_set(60, 4);
  const GaussianProcess gp = train_gaussian_process(data, fixed(2.0, Eigen::Vector3d(0.5, 0.5, 0.5), 1e-4));
  const Evaluation e = gp.evaluate(data.x, {});
  EXPECT_EQ(e.std.size(), 0);
  EXPECT_EQ(e.lo.size(), 0);
  EXPECT_EQ(e.gradient.size(), 0);
  EXPECT_EQ(e.mu.size(), 60);
}

}  // namespace
}  // namespace mufric
