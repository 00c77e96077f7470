// The certified fast evaluator of a GP model file: build time, grid and memory, the bound reached,
// that bound checked on fresh random points, and the cost per point of μ + σ + 95 % interval in a
// batch against the exact GP's, same run, one thread.
//   OMP_NUM_THREADS=1 taskset -c 1 mufric_fast_evaluator_bench MODEL.h5 [FRESH_POINTS] [BATCH]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/models/model_file.hpp"

using namespace mufric;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Eigen::MatrixXd random_points(const InputSpace& box, Eigen::Index count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Eigen::MatrixXd x(count, static_cast<Eigen::Index>(box.size()));
  for (Eigen::Index i = 0; i < count; ++i) {
    for (size_t k = 0; k < box.size(); ++k) x(i, static_cast<Eigen::Index>(k)) = box[k].lo + uniform(rng) * (box[k].hi - box[k].lo);
  }
  return x;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MODEL.h5 [FRESH_POINTS=1000000] [BATCH=10000]\n", argv[0]);
    return 2;
  }
  const Eigen::Index fresh_points = argc > 2 ? std::atol(argv[2]) : 1000000;
  const Eigen::Index batch = argc > 3 ? std::atol(argv[3]) : 10000;
  const auto model = load_model(argv[1]);
  const auto* gp = dynamic_cast<const GaussianProcess*>(model.get());
  if (gp == nullptr) {
    std::fprintf(stderr, "%s is not a Gaussian process\n", argv[1]);
    return 2;
  }
  FastEvaluatorOptions options;
  options.progress = [](const std::string& line) { std::printf("  %s\n", line.c_str()); };
  auto start = std::chrono::steady_clock::now();
  const FastEvaluator fast = build_fast_evaluator(*gp, options);
  const double build_seconds = seconds_since(start);
  std::string shape;
  for (const int c : fast.grid().cells()) {
    if (!shape.empty()) shape += 'x';
    shape += std::to_string(c);
  }
  std::printf("%s: n = %lld, grid %s cells, %.1f MB, built in %.1f s; bound: mu %.3e, std %.3e relative\n", argv[1],
              static_cast<long long>(gp->state().x_train.rows()), shape.c_str(), static_cast<double>(fast.grid().bytes()) / 1e6,
              build_seconds, fast.bounds().mu_absolute, fast.bounds().std_relative);

  const Eigen::MatrixXd fresh = random_points(gp->inputs(), fresh_points, 20261124);
  const FastEvaluatorBounds seen = measure_errors(fast, *gp, fresh);
  std::printf("%lld fresh points: mu error at most %.3e (%s the bound), std %.3e relative (%s)\n",
              static_cast<long long>(fresh_points), seen.mu_absolute,
              seen.mu_absolute <= fast.bounds().mu_absolute ? "within" : "EXCEEDS", seen.std_relative,
              seen.std_relative <= fast.bounds().std_relative ? "within" : "EXCEEDS");

  // Cost per point, mean + std + 95 % interval, one batch, best of five.
  const Eigen::MatrixXd x = random_points(gp->inputs(), batch, 7);
  const double z = normal_quantile_two_sided(0.95);
  double exact_best = 1e300, fast_best = 1e300, checksum = 0.0;
  for (int repeat = 0; repeat < 5; ++repeat) {
    start = std::chrono::steady_clock::now();
    const Evaluation e = gp->evaluate(x, {.std = true, .ci_level = 0.95});
    exact_best = std::min(exact_best, seconds_since(start));
    checksum += e.hi.sum();
    start = std::chrono::steady_clock::now();
    std::vector<double> mu(static_cast<size_t>(batch)), sd(mu.size()), lo(mu.size()), hi(mu.size());
    fast.evaluate(x, mu.data(), sd.data());
    for (size_t i = 0; i < mu.size(); ++i) {
      lo[i] = mu[i] - z * sd[i];
      hi[i] = mu[i] + z * sd[i];
    }
    fast_best = std::min(fast_best, seconds_since(start));
    checksum += hi.back();
  }
  std::printf("mean + std + 95 %% interval, batch %lld, one thread: exact %.3f us/point, fast %.4f us/point, ratio %.0f "
              "(checksum %.3g)\n",
              static_cast<long long>(batch), 1e6 * exact_best / static_cast<double>(batch),
              1e6 * fast_best / static_cast<double>(batch), exact_best / fast_best, checksum);
  return seen.mu_absolute <= fast.bounds().mu_absolute && seen.std_relative <= fast.bounds().std_relative ? 0 : 1;
}
