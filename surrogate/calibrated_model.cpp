#include "surrogate/calibrated_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/error.hpp"
#include "common/units.hpp"
#include "surrogate/fast_evaluator_build.hpp"

namespace mufric {
namespace {

// The exact gradient is a central difference of the exact mean over this fraction of each input's
// box width (one-sided within it of a face): the posterior mean is a sum of RBF terms, smooth on the
// scale of the emulator's length scales (≥ 0.05 box widths), so the truncation error is ~1e-8 relative.
constexpr double kGradientStep = 1e-4;

// The fixed cost of one posterior sample at one point, in the GP's multiply-adds (the unit of a
// fast evaluator's work budget): measured 0.9 µs per sample and point whatever n against the GP's
// 1.0e10 multiply-adds per second on the same core (bench/RESULTS.md, "The calibrated model's exact
// predictive in blocks"), so that a budget means the same time for both.
constexpr double kSamplePointOverheadWork = 1e4;

InputSpace served_inputs(const CalibrationProblem& problem) {
  const GaussianProcess& emulator = problem.emulator();
  InputSpace served;
  for (const std::string& name : problem.data().condition_names) {
    const auto input = std::find_if(emulator.inputs().begin(), emulator.inputs().end(),
                                    [&name](const InputSpec& s) { return s.name == name; });
    if (input == emulator.inputs().end()) throw Error("calibrated model: condition '" + name + "' is not an input of the emulator");
    served.push_back(*input);
  }
  if (served.empty()) throw Error("calibrated model: the measurements give no condition; nothing is left to serve");
  const std::string violation = servable_inputs_violation(problem.data().condition_names);
  if (!violation.empty()) throw Error("calibrated model: " + violation);
  return served;
}

Eigen::VectorXd column_medians(const Eigen::MatrixXd& rows) {
  Eigen::VectorXd medians(rows.cols());
  for (Eigen::Index j = 0; j < rows.cols(); ++j) {
    std::vector<double> values(rows.col(j).data(), rows.col(j).data() + rows.rows());
    std::sort(values.begin(), values.end());
    medians(j) = quantile_of_sorted(values, 0.5);
  }
  return medians;
}

}  // namespace

CalibratedModel::CalibratedModel(std::shared_ptr<const CalibratedPosterior> posterior, CalibrationRecord record)
    : FrictionModel(served_inputs(posterior->problem())),
      emulator_(posterior->problem().emulator_pointer()),
      posterior_(std::move(posterior)),
      record_(std::move(record)) {
  sample_medians_ = column_medians(posterior_->samples());
  Eigen::RowVectorXd centre(inputs().size());
  for (size_t j = 0; j < inputs().size(); ++j) centre(static_cast<Eigen::Index>(j)) = 0.5 * (inputs()[j].lo + inputs()[j].hi);
  centre_parts_ = parts_at(centre);
}

CalibratedPrediction CalibratedModel::predict(const QueryBatch& x, int max_threads) const {
  return posterior_->predict(x, max_threads);
}

IntervalParts CalibratedModel::parts_at(const Eigen::RowVectorXd& x) const {
  const CalibratedPrediction p = predict(x);
  return {p.mean(0), p.sd(0), p.parameter_sd(0), p.conditional_sd(0), p.emulator_sd(0), p.discrepancy_sd(0)};
}

void CalibratedModel::attach_fast_evaluator(std::shared_ptr<const FastEvaluator> fast) {
  if (fast && !same_input_space(fast->box(), inputs())) throw Error("calibrated model: the fast evaluator's box is not the model's");
  fast_ = std::move(fast);
}

Eigen::VectorXd CalibratedModel::unit_length_scales() const {
  Eigen::VectorXd l(static_cast<Eigen::Index>(inputs().size()));
  const double discrepancy_length = problem().discrepancy() ? sample_medians_(problem().discrepancy_offset() + 1)
                                                            : std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < inputs().size(); ++j) {
    const auto at = std::find_if(emulator_->inputs().begin(), emulator_->inputs().end(),
                                 [&](const InputSpec& s) { return s.name == inputs()[j].name; });
    const auto column = static_cast<Eigen::Index>(at - emulator_->inputs().begin());
    l(static_cast<Eigen::Index>(j)) = std::min(emulator_->state().hyper.length_scales(column), discrepancy_length);
  }
  return l;
}

double CalibratedModel::exact_point_work() const {
  // Per kept sample, what the GP's own point costs (its correlations with the campaign and their
  // whitening, GaussianProcess::latent_points), the cross-covariance with the m measurements (n m),
  // its triangular solves with the likelihood's factor (m² each for η and δ), and a fixed cost of
  // small products and exps that dominates at the n of a campaign.
  const double gp_point = mufric::exact_point_work(*emulator_);
  const auto n = static_cast<double>(emulator_->state().x_train.rows());
  const auto m = static_cast<double>(problem().data().mu.size());
  return static_cast<double>(samples().rows()) * (gp_point + n * m + 2.0 * m * m + kSamplePointOverheadWork);
}

void CalibratedModel::evaluate_exact(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  const CalibratedPrediction p = predict(x, what.max_threads);
  out.mu = p.mean;
  if (what.std || what.ci_level > 0.0) out.std = p.sd;
}

void CalibratedModel::evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  const Eigen::Index m = x.rows(), d = x.cols();
  const bool fast = fast_ && !what.exact_only() && fast_->meets(what.mu_tolerance, what.std_relative_tolerance);
  std::vector<Eigen::Index> inside, outside;
  for (Eigen::Index i = 0; i < m && fast; ++i) {
    const Eigen::RowVectorXd row = x.row(i);
    (fast_->inside(row.data()) ? inside : outside).push_back(i);
  }
  if (!fast || inside.empty()) {
    evaluate_exact(x, what, out);
  } else {
    out.mu.resize(m);
    out.std.resize(m);
    for (const Eigen::Index i : inside) {
      const Eigen::RowVectorXd row = x.row(i);
      fast_->evaluate(row.data(), out.mu(i), out.std(i));
    }
    out.fast_points += static_cast<long long>(inside.size());
    if (!outside.empty()) {
      QueryBatch rest(static_cast<Eigen::Index>(outside.size()), d);
      for (size_t r = 0; r < outside.size(); ++r) rest.row(static_cast<Eigen::Index>(r)) = x.row(outside[r]);
      const CalibratedPrediction p = predict(rest, what.max_threads);
      for (size_t r = 0; r < outside.size(); ++r) {
        out.mu(outside[r]) = p.mean(static_cast<Eigen::Index>(r));
        out.std(outside[r]) = p.sd(static_cast<Eigen::Index>(r));
      }
    }
    if (!(what.std || what.ci_level > 0.0)) out.std.resize(0);
  }
  if (what.gradient) {
    // Central differences of the exact mean (one-sided near a face), whatever answered μ.
    out.gradient.resize(m, d);
    for (Eigen::Index k = 0; k < d; ++k) {
      const InputSpec& input = inputs()[static_cast<size_t>(k)];
      const double h = kGradientStep * (input.hi - input.lo);
      QueryBatch plus = x, minus = x;
      Eigen::VectorXd span(m);
      for (Eigen::Index i = 0; i < m; ++i) {
        const bool room_above = x(i, k) + h <= input.hi || x(i, k) > input.hi;
        const bool room_below = x(i, k) - h >= input.lo || x(i, k) < input.lo;
        plus(i, k) = room_above ? x(i, k) + h : x(i, k);
        minus(i, k) = room_below ? x(i, k) - h : x(i, k);
        span(i) = plus(i, k) - minus(i, k);
      }
      out.gradient.col(k) =
          ((predict(plus, what.max_threads).mean - predict(minus, what.max_threads).mean).array() / span.array()).matrix();
    }
  }
}

Eigen::VectorXd CalibratedModel::patch_std_valid(const QueryBatch& x, const EvaluationRequest& what) const {
  // The campaign's patch scatter at the posterior median of θ: how one patch's μ scatters about the
  // mean, a property of the roughness, not of what is known about θ.
  const CalibrationProblem& p = problem();
  const Eigen::VectorXd median_theta = sample_medians_.head(p.parameter_count());
  return emulator_->patch_std(p.emulator_points(x, median_theta),
                              what.exact_only() ? 0.0 : what.std_relative_tolerance);
}

std::optional<TrainingDescription> CalibratedModel::training_description() const {
  std::optional<TrainingDescription> t = emulator_->training_description();
  t->interval = "calibrated";
  t->interval_meaning =
      "posterior predictive of measured friction's mean: the campaign's interval of the mean (roughness draws), "
      "the law coefficients' posterior and the model discrepancy delta given " +
      std::to_string(problem().data().mu.size()) + " measurements";
  t->micro_std_error = 0.0;
  return t;
}

std::optional<CalibrationDescription> CalibratedModel::calibration_description() const {
  CalibrationDescription d;
  d.data_source = record_.data_source;
  d.measurements = problem().data().mu.size();
  d.posterior_samples = samples().rows();
  d.discrepancy = problem().discrepancy();
  for (const ParameterSummary& q : record_.posterior) d.parameters.push_back({q.name, q.mean, q.sd, q.lo95, q.hi95});
  const IntervalParts& c = centre_parts_;
  d.mu = c.mu;
  d.sd = c.sd;
  d.parameter_sd = c.parameter_sd;
  d.conditional_sd = c.conditional_sd;
  d.emulator_sd = c.emulator_sd;
  d.discrepancy_sd = c.discrepancy_sd;
  return d;
}

std::string CalibratedModel::summary() const {
  std::ostringstream s;
  s.precision(4);
  const CalibrationProblem& p = problem();
  s << "calibrated: the posterior predictive of a campaign's GP (" << emulator_->state().x_train.rows() << " samples over";
  for (const InputSpec& input : emulator_->inputs()) s << " " << input.name;
  s << ") given " << p.data().mu.size() << " measurements, " << samples().rows() << " posterior samples, discrepancy "
    << (p.discrepancy() ? "on" : "off") << "\n";
  s << "  measurements: " << record_.data_source << "\n";
  if (!record_.priors.empty()) s << "  priors: " << record_.priors << "\n";
  for (const auto& [name, value] : p.held()) s << "  held: " << name << " = " << format_human(value, kind_of_input(name)) << "\n";
  for (size_t k = 0; k < p.data().data_sets.size(); ++k) {
    s << "  data set " << p.data().data_sets[k] << ": "
      << std::count(p.data().data_set_of_row.begin(), p.data().data_set_of_row.end(), static_cast<int>(k)) << " rows";
    const auto biased = std::find(p.bias_sets().begin(), p.bias_sets().end(), static_cast<int>(k));
    s << (biased == p.bias_sets().end() ? ", no bias" : ", with its own bias") << "\n";
  }
  if (p.latent_count() > 0) {
    s << "  " << p.latent_count() << " measured conditions known only within an uncertainty, sampled with the coefficients\n";
  }
  for (const ParameterSummary& q : record_.posterior) {
    s << "  posterior " << q.name << ": mean " << q.mean << ", sd " << q.sd << ", 95 % " << q.lo95 << " .. " << q.hi95
      << " (split-R^ " << q.split_rhat << ", ESS " << q.effective_sample_size << ")\n";
  }
  s << "  sampler: " << record_.walkers << " walkers x " << record_.steps << " steps after " << record_.burn_in_steps
    << " burn-in, seed " << record_.seed << ", acceptance " << record_.acceptance << "\n";
  const IntervalParts& c = centre_parts_;
  s << "  interval at the box centre: mu " << c.mu << ", sd " << c.sd << " = sqrt(law coefficients' posterior " << c.parameter_sd
    << "^2 + given the coefficients " << c.conditional_sd << "^2); given the data, the roughness mean alone " << c.emulator_sd
    << ", the discrepancy alone " << c.discrepancy_sd
    << " (parts alone need not add up: given the data, what the coefficients explain the discrepancy need not, "
       "and the other way round)\n";
  if (fast_) {
    s << "  fast evaluator: grid";
    for (const int cells : fast_->grid().cells()) s << " " << cells;
    s << " cells, mu within " << fast_->bounds().mu_absolute << ", std within " << fast_->bounds().std_relative << " relative\n";
  } else {
    s << "  no fast evaluator (the exact posterior predictive answers)\n";
  }
  return s.str();
}

}  // namespace mufric
