// Hot paths of the Gaussian process: one LML+gradient evaluation (the unit of fitting cost) and
// prediction per path (mean only, single point with std, small batch, large batch).
//   build/bench/mufric_gp_benchmarks --benchmark_filter=... 
#include <benchmark/benchmark.h>

#include "gp_test_data.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {
namespace {

GaussianProcess fixed_gp(Eigen::Index n) {
  GpTrainingOptions options;
  options.optimise = false;
  options.initial.signal_variance = 100.0;
  options.initial.length_scales = Eigen::Vector3d(3.0, 1.2, 1.4);
  options.initial.noise_variance = 1e-4;
  return train_gaussian_process(test::smooth_training_set(n, 1), options);
}

void LmlWithGradient(benchmark::State& state) {
  const TrainingSet data = test::smooth_training_set(state.range(0), 1);
  const Eigen::MatrixXd u = to_unit_box(data.x, data.inputs);
  const Eigen::VectorXd y = (data.mu.array() - data.mu.mean()) / 0.05;
  LogMarginalLikelihood lml(u, y, true);
  GpHyperParameters h;
  h.signal_variance = 100.0;
  h.length_scales = Eigen::Vector3d(3.0, 1.2, 1.4);
  h.noise_variance = 1e-4;
  const Eigen::VectorXd theta = h.to_log();
  for (auto _ : state) benchmark::DoNotOptimize(lml(theta, true).lml);
}
BENCHMARK(LmlWithGradient)->Arg(256)->Arg(900)->Arg(2000)->Unit(benchmark::kMillisecond);

void Predict(benchmark::State& state, bool with_std) {
  const GaussianProcess gp = fixed_gp(state.range(0));
  const QueryBatch x = test::smooth_training_set(state.range(1), 2).x;
  const EvaluationRequest what{.std = with_std};
  for (auto _ : state) benchmark::DoNotOptimize(gp.evaluate(x, what).mu.data());
  state.SetItemsProcessed(state.iterations() * state.range(1));
}
void PredictMean(benchmark::State& state) { Predict(state, false); }
void PredictMeanStd(benchmark::State& state) { Predict(state, true); }
BENCHMARK(PredictMean)->Args({900, 1})->Args({900, 10000})->Unit(benchmark::kMicrosecond);
BENCHMARK(PredictMeanStd)->Args({300, 1})->Args({900, 1})->Args({900, 8})->Args({900, 10000})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace mufric

BENCHMARK_MAIN();
