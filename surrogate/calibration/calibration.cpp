#include "surrogate/calibration/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "common/error.hpp"

namespace mufric {

double quantile_of_sorted(const std::vector<double>& sorted, double probability) {
  const double position = probability * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, sorted.size() - 1);
  return sorted[below] + (position - static_cast<double>(below)) * (sorted[above] - sorted[below]);
}

CalibrationResult calibrate(const CalibrationProblem& problem, const EnsembleOptions& options, const SamplerProgress& progress) {
  const LogDensity log_posterior = [&problem](const Eigen::VectorXd& c) { return problem.log_posterior(c); };
  EnsembleChains chains = run_ensemble_sampler(log_posterior, problem.draw_start(options.walkers, options.seed), options, progress);
  CalibrationResult result;
  result.options = options;
  result.diagnostics = diagnose_chains(chains);
  result.convergence_failure = convergence_failure(result.diagnostics, problem.coordinate_names(), chains.steps());
  // Not yet within the limits: run on from where the walkers are for as many steps as were run in all,
  // and judge that latest run alone (the earlier steps become its burn-in: "run longer and discard the
  // first half", BDA3 §11.4), while the whole stays within max_steps.
  long long total = options.burn_in_steps + options.steps;
  for (std::uint64_t stage = 1; !result.convergence_failure.empty() && 2 * total <= options.max_steps; ++stage) {
    Eigen::MatrixXd last(options.walkers, problem.dimension());
    for (int w = 0; w < options.walkers; ++w) last.row(w) = chains.states[static_cast<size_t>(w)].bottomRows(1);
    EnsembleOptions more = options;
    more.burn_in_steps = 0;
    more.steps = static_cast<int>(total);
    more.seed = options.seed + stage;
    chains = run_ensemble_sampler(log_posterior, last, more, progress);
    result.options.burn_in_steps = static_cast<int>(total);
    result.options.steps = static_cast<int>(total);
    total *= 2;
    result.diagnostics = diagnose_chains(chains);
    result.convergence_failure = convergence_failure(result.diagnostics, problem.coordinate_names(), chains.steps());
  }
  result.acceptance = chains.acceptance;
  result.samples = chains.pooled();
  if (problem.discrepancy()) {
    result.samples.middleCols(problem.discrepancy_offset(), 2) = result.samples.middleCols(problem.discrepancy_offset(), 2).array().exp().matrix();
  }
  for (Eigen::Index j = 0; j < problem.dimension(); ++j) {
    std::vector<double> values(result.samples.col(j).data(), result.samples.col(j).data() + result.samples.rows());
    std::sort(values.begin(), values.end());
    ParameterSummary s;
    s.name = problem.coordinate_names()[static_cast<size_t>(j)];
    s.mean = result.samples.col(j).mean();
    s.sd = std::sqrt((result.samples.col(j).array() - s.mean).square().sum() / static_cast<double>(values.size() - 1));
    s.lo95 = quantile_of_sorted(values, 0.025);
    s.median = quantile_of_sorted(values, 0.5);
    s.hi95 = quantile_of_sorted(values, 0.975);
    s.split_rhat = result.diagnostics.split_rhat(j);
    s.effective_sample_size = result.diagnostics.effective_sample_size(j);
    result.summary.push_back(s);
  }
  return result;
}

}  // namespace mufric
