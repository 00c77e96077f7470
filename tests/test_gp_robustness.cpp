// Numerical robustness: every case fits or fails with a clear message, never NaN.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "gp_test_data.hpp"
#include "surrogate/core/cholesky.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {
namespace {

void expect_all_finite(const Evaluation& e) {
  EXPECT_TRUE(e.mu.allFinite());
  if (e.std.size()) {
    EXPECT_TRUE(e.std.allFinite());
  }
  if (e.lo.size()) {
    EXPECT_TRUE(e.lo.allFinite() && e.hi.allFinite());
  }
}

TEST(GpRobustness, NearDuplicateInputsWithoutNoiseAddJitterAndReportIt) {
  TrainingSet data = test::smooth_training_set(40, 1);
  // Every point has a twin 1e-13 box widths away with a slightly different μ.
  TrainingSet doubled = data;
  doubled.x.resize(80, 3);
  doubled.mu.resize(80);
  doubled.x.topRows(40) = data.x;
  doubled.x.bottomRows(40) = data.x;
  doubled.x.bottomRows(40).col(0).array() += 1e-13 * 1000e6;
  doubled.mu.head(40) = data.mu;
  doubled.mu.tail(40) = data.mu.array() + 1e-9;
  GpTrainingOptions options;
  options.noise_term = false;
  options.restarts = 1;
  GpTrainingReport report;
  const GaussianProcess gp = train_gaussian_process(doubled, options, &report);
  EXPECT_GT(report.jitter, 0.0);
  EXPECT_EQ(gp.state().jitter, report.jitter);
  bool warned = false;
  for (const auto& w : report.warnings) warned |= w.find("jitter") != std::string::npos;
  EXPECT_TRUE(warned);
  expect_all_finite(gp.evaluate(test::smooth_training_set(50, 2).x, {.std = true, .ci_level = 0.95}));
}

TEST(GpRobustness, ConstantOutputsPredictTheConstantWithAWarning) {
  TrainingSet data = test::smooth_training_set(30, 1);
  data.mu.setConstant(0.42);
  GpTrainingReport report;
  GpTrainingOptions options;
  options.restarts = 1;
  const GaussianProcess gp = train_gaussian_process(data, options, &report);
  ASSERT_FALSE(report.warnings.empty());
  EXPECT_NE(report.warnings.front().find("constant"), std::string::npos);
  const Evaluation e = gp.evaluate(test::smooth_training_set(20, 5).x, {.std = true, .ci_level = 0.95});
  expect_all_finite(e);
  for (Eigen::Index i = 0; i < 20; ++i) EXPECT_NEAR(e.mu(i), 0.42, 1e-12);
}

bool warns_of(const GpTrainingReport& report, const std::string& words) {
  return std::any_of(report.warnings.begin(), report.warnings.end(),
                     [&](const std::string& w) { return w.find(words) != std::string::npos; });
}

// Regression: a fit that explains nothing (all noise) was reported like any other. Pure noise is such
// a fit whatever the optimiser does; a smooth field is not.
TEST(GpRobustness, AFitThatExplainsNothingSaysSo) {
  TrainingSet noise = test::smooth_training_set(60, 3);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.2, 0.01);
  for (Eigen::Index i = 0; i < noise.mu.size(); ++i) noise.mu(i) = normal(rng);
  GpTrainingOptions options;
  options.restarts = 1;
  GpTrainingReport report;
  train_gaussian_process(noise, options, &report);
  EXPECT_TRUE(warns_of(report, "the fit explains almost nothing")) << ::testing::PrintToString(report.warnings);
  EXPECT_TRUE(warns_of(report, "try the default --restarts"));
  GpTrainingReport smooth;
  train_gaussian_process(test::smooth_training_set(60, 3), options, &smooth);
  EXPECT_FALSE(warns_of(smooth, "explains almost nothing")) << ::testing::PrintToString(smooth.warnings);
}

TEST(GpRobustness, SinglePointMatchesClosedForm) {
  TrainingSet data = test::smooth_training_set(1, 1);
  GpTrainingOptions options;
  options.optimise = false;
  options.initial.signal_variance = 2.0;
  options.initial.length_scales = Eigen::Vector3d(0.5, 0.5, 0.5);
  options.initial.noise_variance = 0.1;
  const GaussianProcess gp = train_gaussian_process(data, options);
  const TrainingSet q = test::smooth_training_set(5, 3);
  const Evaluation e = gp.evaluate(q.x, {.std = true});
  const Eigen::MatrixXd u0 = to_unit_box(data.x, data.inputs), uq = to_unit_box(q.x, data.inputs);
  for (Eigen::Index i = 0; i < 5; ++i) {
    // Normalised y is 0 (single value, scale 1): mean is y₁; var = σ² + σn² − σ⁴k̂²/(σ² + σn²).
    const double k = std::exp(-0.5 * ((uq.row(i) - u0.row(0)).array() / 0.5).square().sum());
    EXPECT_NEAR(e.mu(i), data.mu(0), 1e-14);
    EXPECT_NEAR(e.std(i), std::sqrt(2.1 - 4.0 * k * k / 2.1), 1e-12);
  }
}

TEST(GpRobustness, InputsSpanningTwelveOrdersOfMagnitudeFitWithoutNaN) {
  TrainingSet data;
  data.inputs = {{"x", "1", 1e-6, 1e6}};
  const Eigen::Index n = 60;
  data.x.resize(n, 1);
  data.mu.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    data.x(i, 0) = std::pow(10.0, -6.0 + 12.0 * static_cast<double>(i) / static_cast<double>(n - 1));
    data.mu(i) = 0.3 + 0.05 * std::log10(data.x(i, 0)) / 6.0;
  }
  GpTrainingOptions options;
  options.restarts = 2;
  GpTrainingReport report;
  const GaussianProcess gp = train_gaussian_process(data, options, &report);
  EXPECT_TRUE(std::isfinite(gp.state().summary.log_marginal_likelihood));
  expect_all_finite(gp.evaluate(data.x, {.std = true, .ci_level = 0.95, .gradient = true}));
}

TEST(GpRobustness, FiveThousandPointsFitAndReproduceTheData) {
  const TrainingSet data = test::smooth_training_set(5000, 17);
  GpTrainingOptions options;
  options.optimise = false;
  options.initial.signal_variance = 1.0;
  options.initial.length_scales = Eigen::Vector3d(0.8, 0.8, 0.8);
  options.initial.noise_variance = 1e-6;
  const auto t0 = std::chrono::steady_clock::now();
  const GaussianProcess gp = train_gaussian_process(data, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("5000-point fit with fixed hyper-parameters: %.2f s\n", seconds);
  const Evaluation e = gp.evaluate(data.x.topRows(500), {.std = true});
  expect_all_finite(e);
  EXPECT_LT((e.mu - data.mu.head(500)).cwiseAbs().maxCoeff(), 1e-3);
}

// A long fit says what it is doing: each stage, then (here every evaluation) its starts' climbs.
TEST(GpRobustness, TrainingReportsItsProgress) {
  GpTrainingOptions options;
  options.restarts = 1;
  options.threads = 2;
  options.progress_seconds = 0.0;
  std::vector<std::string> lines;
  options.progress = [&](const std::string& line) { lines.push_back(line); };  // serialised by the trainer
  GpTrainingReport report;
  train_gaussian_process(test::smooth_training_set(600, 3), options, &report);
  ASSERT_GE(lines.size(), 3u);
  EXPECT_NE(lines[0].find("on a subset of 256 of the 600 points"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find("on all 600 points"), std::string::npos) << lines[1];
  int climbs = 0;
  for (const auto& start : report.starts) climbs += start.outcome.find("same basin") == std::string::npos &&
                                                    start.outcome.find("not refined") == std::string::npos
                                                    ? start.evaluations : 0;
  EXPECT_EQ(static_cast<int>(lines.size()) - 2, climbs);
  EXPECT_NE(lines[2].find("LML evaluations in"), std::string::npos) << lines[2];
}

TEST(GpRobustness, NonFiniteTrainingDataIsRefusedWithAMessage) {
  TrainingSet data = test::smooth_training_set(10, 1);
  data.mu(3) = std::nan("");
  EXPECT_THROW(
      {
        try {
          train_gaussian_process(data, {});
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos);
          throw;
        }
      },
      Error);
}

TEST(GpRobustness, IndefiniteMatrixFailsWithAReasonAfterBoundedJitter) {
  Eigen::MatrixXd a(2, 2);
  a << 1.0, 2.0, 2.0, 1.0;  // eigenvalues 3 and −1: no small jitter can help
  Eigen::MatrixXd factor;
  const CholeskyOutcome outcome = cholesky_with_jitter(a, 0.0, factor);
  EXPECT_FALSE(outcome.ok);
  EXPECT_GT(outcome.attempts, 1);
  EXPECT_LE(outcome.attempts, 10);  // 1e-12 … 1e-4 relative, ×10 each
  EXPECT_NE(outcome.reason.find("not positive definite"), std::string::npos);
}

TEST(GpRobustness, NegativePredictiveVariancesAreClampedAndCounted) {
  const TrainingSet data = test::smooth_training_set(30, 1);
  GpTrainingOptions options;
  options.optimise = false;
  options.noise_term = false;
  options.initial.length_scales = Eigen::Vector3d(0.5, 0.5, 0.5);
  GaussianProcess::State state = train_gaussian_process(data, options).state();
  // A factor 0.1 % too small makes σ⁴|L⁻¹k|² exceed σ² at the training points.
  state.cholesky *= 0.999;
  const GaussianProcess tampered(std::move(state));
  const Evaluation e = tampered.evaluate(data.x, {.std = true});
  EXPECT_EQ(e.clamped_variances, 30);
  EXPECT_TRUE((e.std.array() == 0.0).all());
}

TEST(GpRobustness, EmptyInputBoxIsRefusedNamingTheInput) {
  TrainingSet data = test::smooth_training_set(10, 1);
  data.inputs[2].hi = data.inputs[2].lo;
  try {
    train_gaussian_process(data, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("temperature"), std::string::npos);
  }
}

}  // namespace
}  // namespace mufric
