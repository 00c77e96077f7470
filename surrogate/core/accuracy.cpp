#include "surrogate/core/accuracy.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include "common/error.hpp"
#include "common/version.hpp"
#include "surrogate/core/sampling.hpp"

namespace mufric {
QueryBatch align_inputs(const Eigen::MatrixXd& x, const InputSpace& from, const InputSpace& to, const std::string& where) {
  QueryBatch aligned(x.rows(), static_cast<Eigen::Index>(to.size()));
  for (size_t j = 0; j < to.size(); ++j) {
    auto it = std::find_if(from.begin(), from.end(), [&](const InputSpec& s) { return s.name == to[j].name; });
    if (it == from.end()) throw Error(where + ": has no input '" + to[j].name + "' that the model needs");
    aligned.col(static_cast<Eigen::Index>(j)) = x.col(it - from.begin());
  }
  return aligned;
}

AccuracyReport held_out_accuracy(const FrictionModel& model, const TrainingSet& test, double level) {
  AccuracyReport report;
  report.level = level;
  const QueryBatch x = align_inputs(test.x, test.inputs, model.inputs(), test.source_path);
  const auto t0 = std::chrono::steady_clock::now();
  const Evaluation e = model.evaluate(x, {.std = false, .ci_level = level, .gradient = false});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Eigen::Index n = x.rows();
  report.points = n;
  report.seconds_per_point = n > 0 ? seconds / static_cast<double>(n) : 0.0;
  double sum_rel = 0.0, sum_sq = 0.0;
  long long covered = 0, answered = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto status = e.status[static_cast<size_t>(i)];
    if (status == PointStatus::invalid_input) continue;
    if (status == PointStatus::extrapolated) ++report.extrapolated;
    ++answered;
    const double error = e.mu(i) - test.mu(i);
    const double rel = relative_error(error, test.mu(i));
    sum_rel += rel;
    report.max_relative_error = std::max(report.max_relative_error, rel);
    sum_sq += error * error;
    if (test.mu(i) >= e.lo(i) && test.mu(i) <= e.hi(i)) ++covered;
  }
  if (answered == 0) throw Error(test.source_path + ": no valid test points");
  report.mean_relative_error = sum_rel / static_cast<double>(answered);
  report.rmse = std::sqrt(sum_sq / static_cast<double>(answered));
  report.coverage = static_cast<double>(covered) / static_cast<double>(answered);
  return report;
}

Dataset sample_model(const FrictionModel& model, const SamplingOptions& options, const std::string& source) {
  if (options.samples <= 0) throw Error("--samples must be positive");
  const auto n = static_cast<Eigen::Index>(options.samples);
  const auto d = static_cast<Eigen::Index>(model.inputs().size());
  std::mt19937_64 rng(options.seed);
  Dataset data;
  data.inputs = model.inputs();
  const Eigen::MatrixXd u = latin_hypercube(n, d, rng);
  data.x.resize(n, d);
  for (Eigen::Index j = 0; j < d; ++j) {
    const auto& input = data.inputs[static_cast<size_t>(j)];
    data.x.col(j) = (input.lo + u.col(j).array() * (input.hi - input.lo)).matrix();
  }
  const Evaluation e = model.evaluate(data.x, {});
  data.mu = e.mu;
  if (options.noise_std > 0.0) {
    std::normal_distribution<double> noise(0.0, options.noise_std);
    for (Eigen::Index i = 0; i < n; ++i) data.mu(i) += noise(rng);
  }
  data.status.assign(static_cast<size_t>(n), static_cast<long long>(SampleStatus::converged));
  data.failure_reason.assign(static_cast<size_t>(n), "");
  data.plan = data.x;
  data.source = source;
  data.code_version = code_version();
  return data;
}

}  // namespace mufric
