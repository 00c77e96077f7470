// The --fast-* options of train, upgrade and calibrate, and the one policy by which each builds,
// reports and keeps (or not) a model's fast evaluator.
#include "app/fast_evaluator_options.hpp"

#include <chrono>
#include <cstdio>

#include "app/commands.hpp"
#include "surrogate/gp/gp_grids.hpp"

namespace mufric::app {

void add_fast_evaluator_options(CLI::App* cmd, FastOptions& o) {
  // Positive and finite (PositiveNumber let "inf" through): a tolerance below rounding cannot be
  // met, and a budget of 0 builds nothing.
  constexpr double kLeastTolerance = 1e-15, kLeastBudget = 1e-3;
  cmd->add_option("--fast-mu-tolerance", o.build.mu_tolerance,
                  "Fast evaluator: refine until its measured bound on mu is within this (absolute)")
      ->capture_default_str()->check(FiniteRange(kLeastTolerance, 1.0));
  cmd->add_option("--fast-std-tolerance", o.build.std_relative_tolerance,
                  "Fast evaluator: ... and its bound on std within this fraction of max(std, F), where\n"
                  "F = mu tolerance / std tolerance: the interval's bounds mu +- z std are then accurate to\n"
                  "this fraction of the half-width, or to the mu tolerance where std is smaller than F")
      ->capture_default_str()->check(FiniteRange(kLeastTolerance, 1.0));
  cmd->add_option("--fast-max-mb", o.build.max_megabytes, "Fast evaluator: largest grid, MB")
      ->capture_default_str()->check(FiniteRange(kLeastBudget, 1e6));
  cmd->add_option("--fast-max-work", o.max_gigawork,
                  "Fast evaluator: work budget in 10^9 multiply-adds of the exact model (about 0.1 s each on one\n"
                  "core with AVX2); a finer grid that would take the build past it is not built. Counted, not timed:\n"
                  "the same data and command give the same file on a busy machine and an idle one\n"
                  "(default: 100 n^3 for a GP of n points, at least 3000; 3000 for a calibrated model)")
      ->check(FiniteRange(kLeastBudget, 1e9));
  cmd->add_flag("--no-fast-evaluator", o.skip, "Store no fast evaluator: the exact model answers every request");
}

std::shared_ptr<const FastEvaluator> build_fast_evaluator(const GridSource& source, FastEvaluatorOptions build,
                                                          const std::string& label) {
  build.progress = [label](const std::string& line) {
    std::printf("  fast evaluator (%s): %s\n", label.c_str(), line.c_str());
    std::fflush(stdout);
  };
  std::printf("fast evaluator (%s): building within %.3g G multiply-adds and %.0f MB (--fast-max-work, --fast-max-mb)\n",
              label.c_str(), build.max_work / 1e9, build.max_megabytes);
  const auto start = std::chrono::steady_clock::now();
  std::shared_ptr<const FastEvaluator> fast;
  try {
    fast = std::make_shared<const FastEvaluator>(mufric::build_fast_evaluator(source, build));
  } catch (const FastEvaluatorOverCap& e) {
    // Regression: train exited here with no model written at all.
    std::printf("fast evaluator (%s): not stored: %s; the exact model answers every request (a larger "
                "--fast-max-mb with `mufric upgrade --rebuild`)\n", label.c_str(), e.what());
    return nullptr;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (const std::string refusal = short_grid_refusal(*fast, build); !refusal.empty()) {
    std::printf("fast evaluator (%s): not stored, built in %.1f s: %s, %s; the exact model answers every request "
                "(a larger --fast-max-work / --fast-max-mb, or looser --fast-*-tolerance, with `mufric upgrade --rebuild`)\n",
                label.c_str(), seconds, fast->stop_reason().c_str(), refusal.c_str());
    return nullptr;
  }
  if (!fast->meets(build.mu_tolerance, build.std_relative_tolerance)) {
    std::printf("fast evaluator (%s): %.1f MB, built in %.1f s; stopped short (%s) at mu within %.3g, std within %.3g "
                "relative: requests that ask no more use it, the others the exact model\n",
                label.c_str(), static_cast<double>(fast->grid().bytes()) / 1e6, seconds, fast->stop_reason().c_str(),
                fast->bounds().mu_absolute, fast->bounds().std_relative);
    return fast;
  }
  std::printf("fast evaluator (%s): %.1f MB, built in %.1f s; meets the tolerances: it answers default requests inside "
              "the box\n",
              label.c_str(), static_cast<double>(fast->grid().bytes()) / 1e6, seconds);
  return fast;
}

void attach_fast_evaluator(GaussianProcess& gp, const FastOptions& o) {
  if (o.skip) {
    gp.attach_fast_evaluator(nullptr);  // never keep a grid of another fit or range
    if (gp.patch_scatter()) gp.attach_patch_scatter_fast_evaluator(nullptr);
    return;
  }
  FastEvaluatorOptions build = o.build;
  build.max_work = o.max_gigawork > 0.0 ? o.max_gigawork * 1e9 : 0.0;  // 0: the GP's default
  attach_fast_evaluators(gp, build, [](const GridSource& source, const FastEvaluatorOptions& options, const std::string& label) {
    return build_fast_evaluator(source, options, label);
  });
}

void attach_fast_evaluator(CalibratedModel& model, const FastOptions& o) {
  model.attach_fast_evaluator(nullptr);
  if (o.skip) return;
  FastEvaluatorOptions build = o.build;
  build.max_work = o.max_gigawork > 0.0 ? o.max_gigawork * 1e9 : kLeastFastEvaluatorWork;
  std::printf("fast evaluator (calibrated model): %.3g M multiply-adds a point of the exact posterior predictive\n",
              model.exact_point_work() / 1e6);
  model.attach_fast_evaluator(
      build_fast_evaluator(GridSource{model, model.unit_length_scales(), model.exact_point_work()}, build, "calibrated model"));
}

}  // namespace mufric::app
