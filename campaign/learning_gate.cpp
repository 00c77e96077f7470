#include "campaign/learning_gate.hpp"

#include <algorithm>
#include <cmath>

#include "common/wording.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {
namespace {

constexpr double kCoverageLevel = 0.95;
constexpr double kZ95 = 1.959963984540054;

}  // namespace

double binomial_lower_tail(long long k, long long n, double p) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  double sum = 0.0;
  for (long long i = 0; i <= k; ++i) {
    const double log_pmf = std::lgamma(static_cast<double>(n) + 1.0) - std::lgamma(static_cast<double>(i) + 1.0) -
                           std::lgamma(static_cast<double>(n - i) + 1.0) + static_cast<double>(i) * std::log(p) +
                           static_cast<double>(n - i) * std::log1p(-p);
    sum += std::exp(log_pmf);
  }
  return std::min(sum, 1.0);
}

namespace {

// A gate's decision and its verdict's first words; the figures it rests on (gate_figures) follow
// unless the verdict came before any (another input space, another database).
struct Judged {
  GateDecision decision;
  std::string verdict;
  bool figures_follow = false;
};

std::string gate_figures(const GateDecision& g) {
  std::string figures = text_printf("leave-one-out RMSE on the served version's %lld points %.3g (served %.3g, at most %.3g); "
                               "%lld of %lld new points inside their 95 %% interval",
                               g.old_points, g.candidate_loo_rmse, g.served_loo_rmse, g.allowed_loo_rmse, g.new_covered, g.new_points);
  if (g.measurements > 0) {
    figures += text_printf("; recalibrated: %lld of %lld measurements inside the 95 %% predictive interval", g.measurements_covered,
                      g.measurements);
  }
  return figures;
}

// gate_candidate's checks.
Judged judge_candidate(const GaussianProcess& served, const GaussianProcess& candidate, const FastEvaluatorOptions& tolerances) {
  Judged judged;
  GateDecision& g = judged.decision;
  std::string& why = judged.verdict;
  // The box may have grown; the inputs must still be the same names in the same order.
  if (input_names(served.inputs()) != input_names(candidate.inputs())) {
    why = "the candidate's inputs are not the served model's";
    return judged;
  }
  const auto& old_state = served.state();
  const auto& new_state = candidate.state();
  const LeaveOneOut old_loo = leave_one_out_points(old_state), new_loo = leave_one_out_points(new_state);
  if (old_loo.error.size() == 0 || new_loo.error.size() == 0) {
    why = "leave-one-out could not be computed (a factor could not be inverted)";
    return judged;
  }
  // The candidate's rows at the served version's points (the same samples: same SI coordinates).
  std::map<std::vector<double>, Eigen::Index> candidate_row;
  for (Eigen::Index i = 0; i < new_state.x_train.rows(); ++i) {
    const Eigen::VectorXd row = new_state.x_train.row(i);
    candidate_row.emplace(std::vector<double>(row.data(), row.data() + row.size()), i);
  }
  std::vector<bool> is_old(static_cast<size_t>(new_state.x_train.rows()), false);
  double old_sq = 0.0, new_sq = 0.0;
  for (Eigen::Index i = 0; i < old_state.x_train.rows(); ++i) {
    const Eigen::VectorXd row = old_state.x_train.row(i);
    const auto it = candidate_row.find(std::vector<double>(row.data(), row.data() + row.size()));
    if (it == candidate_row.end()) continue;
    is_old[static_cast<size_t>(it->second)] = true;
    ++g.old_points;
    old_sq += old_loo.error(i) * old_loo.error(i);
    new_sq += new_loo.error(it->second) * new_loo.error(it->second);
  }
  if (g.old_points < old_state.x_train.rows()) {
    why = text_printf("the candidate was not trained on all the served version's points (%lld of %lld found): another database",
                 g.old_points, static_cast<long long>(old_state.x_train.rows()));
    return judged;
  }
  const double n = static_cast<double>(g.old_points);
  g.served_loo_rmse = std::sqrt(old_sq / n);
  g.candidate_loo_rmse = std::sqrt(new_sq / n);
  g.allowed_loo_rmse = g.served_loo_rmse * (1.0 + kGateRmseSlack / std::sqrt(2.0 * n));
  for (Eigen::Index i = 0; i < new_state.x_train.rows(); ++i) {
    if (is_old[static_cast<size_t>(i)]) continue;
    ++g.new_points;
    if (std::abs(new_loo.error(i)) <= kZ95 * new_loo.std(i)) ++g.new_covered;
  }
  const FastEvaluator* served_grid = served.fast_evaluator();
  const FastEvaluator* candidate_grid = candidate.fast_evaluator();
  const bool served_certified = served_grid != nullptr && served_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance);
  g.grid_certified = !served_certified || (candidate_grid != nullptr && candidate_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance));
  judged.figures_follow = true;
  if (g.new_points == 0) {
    why = "the round added no converged point; ";
  } else if (g.candidate_loo_rmse > g.allowed_loo_rmse) {
    why = "worse on what the served version knew: ";
    g.values_refused = true;
  } else if (binomial_lower_tail(g.new_covered, g.new_points, kCoverageLevel) < kGateCoverageSignificance) {
    why = text_printf("its interval misses its new points more often than a 95 %% interval may (binomial p < %g): ", kGateCoverageSignificance);
    g.values_refused = true;
  } else if (!g.grid_certified) {
    why = "its fast evaluator does not meet the tolerances the served one met; ";
  } else {
    g.publish = true;
    why = "no worse: ";
  }
  return judged;
}

// Of a calibrated model's measurements, those inside its 95 % posterior predictive interval widened
// by the measurement's own SD (the predictive is of the true μ; a measurement scatters about it).
long long measurements_covered(const CalibratedModel& model) {
  const Measurements& data = model.problem().data();
  EvaluationRequest exact;
  exact.std = true;
  exact.mu_tolerance = 0.0;  // the exact predictive, not a grid of it
  const Evaluation e = model.evaluate(data.conditions, exact);
  long long covered = 0;
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    covered += std::abs(data.mu(i) - e.mu(i)) <= kZ95 * std::hypot(e.std(i), data.mu_sd(i));
  }
  return covered;
}

}  // namespace

GateDecision gate_candidate(const GaussianProcess& served, const GaussianProcess& candidate, const FastEvaluatorOptions& tolerances) {
  Judged judged = judge_candidate(served, candidate, tolerances);
  judged.decision.reason = judged.verdict + (judged.figures_follow ? gate_figures(judged.decision) : "");
  return judged.decision;
}

GateDecision gate_calibrated_candidate(const CalibratedModel& served, const CalibratedModel& candidate,
                                       const FastEvaluatorOptions& tolerances) {
  Judged judged = judge_candidate(served.emulator(), candidate.emulator(), tolerances);  // emulators: no grid in the file
  GateDecision& g = judged.decision;
  g.measurements = candidate.problem().data().rows();
  g.measurements_covered = measurements_covered(candidate);
  const long long served_covered = measurements_covered(served);
  const FastEvaluator* served_grid = served.fast_evaluator();
  const FastEvaluator* candidate_grid = candidate.fast_evaluator();
  g.grid_certified = served_grid == nullptr || !served_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance) ||
                     (candidate_grid != nullptr && candidate_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance));
  // A data set with a bias of its own may leave the served version's coverage short of 95 %: the
  // candidate is refused only for a shortfall it adds.
  if (g.publish && g.measurements_covered < served_covered &&
      binomial_lower_tail(g.measurements_covered, g.measurements, kCoverageLevel) < kGateCoverageSignificance) {
    g.publish = false;
    g.values_refused = true;
    judged.verdict = text_printf("its posterior predictive misses the measurements more often than a 95 %% interval may (binomial p < %g) "
                            "and more often than the served version's: ", kGateCoverageSignificance);
  } else if (g.publish && !g.grid_certified) {
    g.publish = false;
    judged.verdict = "its fast evaluator does not meet the tolerances the served one met; ";
  }
  g.reason = judged.verdict + (judged.figures_follow ? gate_figures(g) + text_printf(" (served %lld)", served_covered) : "");
  return g;
}

}  // namespace mufric
