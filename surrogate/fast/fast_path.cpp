#include "surrogate/fast/fast_path.hpp"

#include <vector>

namespace mufric {
namespace {

QueryBatch rows_of(const QueryBatch& x, const std::vector<Eigen::Index>& which) { return x(which, Eigen::all); }

}  // namespace

bool grid_serves(const FastEvaluator* fast, const EvaluationRequest& what) {
  return fast != nullptr && !what.exact_only() && fast->meets(what.mu_tolerance, what.std_relative_tolerance);
}

void evaluate_through_grid(const FastEvaluator* fast, const QueryBatch& x, const EvaluationRequest& what,
                           const ExactEvaluation& exact, Evaluation& out) {
  if (!grid_serves(fast, what)) {
    exact(x, what, out);
    return;
  }
  const Eigen::Index m = x.rows(), d = x.cols();
  std::vector<Eigen::Index> inside, outside;
  for (Eigen::Index i = 0; i < m; ++i) {
    double point[TensorCubicGrid::kMaximumInputs];
    for (Eigen::Index k = 0; k < d; ++k) point[k] = x(i, k);
    (fast->inside(point) ? inside : outside).push_back(i);
  }
  if (inside.empty()) {
    exact(x, what, out);
    return;
  }
  const bool need_std = what.std || what.ci_level > 0.0;
  if (what.gradient) {
    exact(x, what, out);  // every row's gradient, and μ and σ of the rows outside the box
  } else {
    out.mu.resize(m);
    if (need_std) out.std.resize(m);
    if (!outside.empty()) {
      Evaluation rest;
      exact(rows_of(x, outside), what, rest);
      for (size_t r = 0; r < outside.size(); ++r) {
        out.mu(outside[r]) = rest.mu(static_cast<Eigen::Index>(r));
        if (need_std) out.std(outside[r]) = rest.std(static_cast<Eigen::Index>(r));
      }
      out.clamped_variances += rest.clamped_variances;
    }
  }
  const QueryBatch in_box = outside.empty() ? QueryBatch() : rows_of(x, inside);
  const QueryBatch& grid_rows = outside.empty() ? x : in_box;
  Eigen::VectorXd mu(grid_rows.rows()), sd(grid_rows.rows());
  fast->evaluate(grid_rows, mu.data(), sd.data());
  for (size_t r = 0; r < inside.size(); ++r) {
    out.mu(inside[r]) = mu(static_cast<Eigen::Index>(r));
    if (need_std) out.std(inside[r]) = sd(static_cast<Eigen::Index>(r));
  }
  out.fast_points += static_cast<long long>(inside.size());
}

}  // namespace mufric
