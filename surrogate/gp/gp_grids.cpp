#include "surrogate/gp/gp_grids.hpp"

#include <algorithm>

namespace mufric {

double exact_point_work(const GaussianProcess& gp) {
  const auto n = static_cast<double>(gp.state().x_train.rows());
  const auto d = static_cast<double>(gp.inputs().size());
  return n * (n + d);
}

GridSource grid_source(const GaussianProcess& gp) { return {gp, gp.state().hyper.length_scales, exact_point_work(gp)}; }

FastEvaluator build_fast_evaluator(const GaussianProcess& gp, const FastEvaluatorOptions& options) {
  return build_fast_evaluator(grid_source(gp), options);
}

double default_fast_evaluator_work(Eigen::Index training_points) {
  const auto n = static_cast<double>(training_points);
  return std::max(kLeastFastEvaluatorWork, kFitLikeEvaluations * n * n * n);
}

void attach_fast_evaluators(GaussianProcess& gp, FastEvaluatorOptions options, const GridBuilder& build) {
  gp.attach_fast_evaluator(nullptr);
  if (gp.patch_scatter()) gp.attach_patch_scatter_fast_evaluator(nullptr);
  if (!(options.max_work > 0.0)) options.max_work = default_fast_evaluator_work(gp.state().x_train.rows());
  gp.attach_fast_evaluator(build(grid_source(gp), options, "model"));
  if (gp.patch_scatter()) {
    FastEvaluatorOptions scatter = options;
    scatter.mu_tolerance = patch_scatter_log_variance_tolerance(options.std_relative_tolerance);
    scatter.std_relative_tolerance = 1.0;
    gp.attach_patch_scatter_fast_evaluator(build(grid_source(*gp.patch_scatter()), scatter, "patch scatter"));
  }
}

}  // namespace mufric
