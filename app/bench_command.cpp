// `mufric bench`: evaluation throughput and latency of a model, in-process.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "surrogate/model_file.hpp"

namespace mufric::app {
namespace {

QueryBatch random_points(const InputSpace& inputs, Eigen::Index count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  QueryBatch x(count, static_cast<Eigen::Index>(inputs.size()));
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    const auto& input = inputs[static_cast<size_t>(j)];
    for (Eigen::Index i = 0; i < count; ++i) x(i, j) = input.lo + unit(rng) * (input.hi - input.lo);
  }
  return x;
}

}  // namespace

void add_bench_command(CLI::App& app) {
  struct Options {
    std::string model;
    std::vector<long long> batches{1, 64, 1024, 16384};
    double seconds = 1.0;
    bool with_std = false;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("bench", "Evaluation throughput and latency of a model (in-process)");
  cmd->add_option("--model", o->model, "Model file or file:// URI")->required();
  cmd->add_option("--batch", o->batches, "Batch sizes (points per call)")->capture_default_str()->expected(1, 16);
  cmd->add_option("--seconds", o->seconds, "Minimum measuring time per batch size")->capture_default_str()
      ->check(CLI::Range(0.01, 600.0));
  cmd->add_flag("--std", o->with_std, "Also compute the standard deviation (and a 95 % interval)");
  cmd->add_flag("--json", o->json, "One JSON object per batch size instead of a table");
  cmd->callback([o] {
    const auto model = load_model(model_path_from_uri(o->model));
    const EvaluationRequest what{.std = o->with_std, .ci_level = o->with_std ? 0.95 : 0.0, .gradient = false};
    if (!o->json) std::printf("%10s %12s %14s %12s %12s   (%s, %s)\n", "batch", "calls", "points/s", "p50 [us]", "p99 [us]",
                              o->model.c_str(), o->with_std ? "mean+std" : "mean only");
    for (const long long batch : o->batches) {
      if (batch <= 0) throw Error("--batch: sizes must be positive");
      const QueryBatch x = random_points(model->inputs(), batch, 7);
      model->evaluate(x, what);  // warm-up: page in caches and the thread pool
      std::vector<double> latencies;
      const auto start = std::chrono::steady_clock::now();
      double elapsed = 0.0;
      double sink = 0.0;
      while (elapsed < o->seconds || latencies.size() < 5) {
        const auto t0 = std::chrono::steady_clock::now();
        const Evaluation e = model->evaluate(x, what);
        const auto t1 = std::chrono::steady_clock::now();
        sink += e.mu(0);
        latencies.push_back(std::chrono::duration<double>(t1 - t0).count());
        elapsed = std::chrono::duration<double>(t1 - start).count();
      }
      std::sort(latencies.begin(), latencies.end());
      double total = 0.0;
      for (double l : latencies) total += l;
      const double p50 = latencies[latencies.size() / 2];
      const double p99 = latencies[std::min(latencies.size() - 1, latencies.size() * 99 / 100)];
      const double points_per_second = static_cast<double>(batch) * static_cast<double>(latencies.size()) / total;
      if (o->json) {
        std::printf("{\"batch\": %lld, \"calls\": %zu, \"points_per_second\": %.6g, \"p50_us\": %.4g, \"p99_us\": %.4g, "
                    "\"std\": %s}\n",
                    batch, latencies.size(), points_per_second, 1e6 * p50, 1e6 * p99, o->with_std ? "true" : "false");
      } else {
        std::printf("%10lld %12zu %14.4g %12.4g %12.4g\n", batch, latencies.size(), points_per_second, 1e6 * p50, 1e6 * p99);
      }
      if (sink == 12345.678) std::printf(" ");  // keeps the evaluations observable to the optimiser
    }
  });
}

}  // namespace mufric::app
