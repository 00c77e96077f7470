#include "surrogate/calibration/calibrated_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/error.hpp"
#include "common/units.hpp"
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/fast/fast_evaluator_file.hpp"
#include "surrogate/fast/fast_path.hpp"

namespace mufric {
namespace {

// The exact gradient is a central difference of the exact mean over this fraction of each input's
// box width (one-sided within it of a face): the posterior mean is a sum of RBF terms, smooth on the
// scale of the emulator's length scales (≥ 0.05 box widths), so the truncation error is ~1e-8 relative.
constexpr double kGradientStep = 1e-4;

// The fixed cost of one posterior sample at one point, in the GP's multiply-adds (the unit of a
// fast evaluator's work budget): measured 0.9 µs per sample and point whatever n against the GP's
// 1.0e10 multiply-adds per second on the same core (bench/studies/calibration/README.md, "The calibrated model's exact
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
  if (what.gradient) {
    // Central differences of the exact mean (one-sided near a face).
    const Eigen::Index m = x.rows(), d = x.cols();
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

void CalibratedModel::evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  evaluate_through_grid(
      fast_.get(), x, what, [this](const QueryBatch& rows, const EvaluationRequest& w, Evaluation& e) { evaluate_exact(rows, w, e); },
      out);
}

Eigen::VectorXd CalibratedModel::patch_std_valid(const QueryBatch& x, const EvaluationRequest& what) const {
  // The campaign's patch scatter at the posterior median of θ: how one patch's μ scatters about the
  // mean, a property of the roughness, not of what is known about θ.
  const CalibrationProblem& p = problem();
  const Eigen::VectorXd median_theta = sample_medians_.head(p.parameter_count());
  return emulator_->patch_std(p.emulator_points(x, median_theta),
                              what.exact_only() ? 0.0 : what.std_relative_tolerance);
}

KindDescription CalibratedModel::kind_description() const {
  KindDescription out{.training = emulator_->kind_description().training, .calibration = CalibrationDescription{}};
  std::optional<TrainingDescription>& t = out.training;
  t->interval = "calibrated";
  t->interval_meaning =
      "posterior predictive of measured friction's mean: the campaign's interval of the mean (roughness draws), "
      "the law coefficients' posterior and the model discrepancy delta given " +
      std::to_string(problem().data().mu.size()) + " measurements";
  t->micro_std_error = 0.0;
  CalibrationDescription& d = *out.calibration;
  d.data_source = record_.data_source;
  d.measurements = problem().data().mu.size();
  d.posterior_samples = samples().rows();
  d.discrepancy = problem().discrepancy();
  for (const ParameterSummary& q : record_.posterior) d.parameters.push_back({q.name, q.mean, q.sd, q.lo95, q.hi95});
  d.at_box_centre = centre_parts_;
  return out;
}

std::string CalibratedModel::summary() const {
  std::ostringstream s;
  s.precision(4);
  const CalibrationProblem& p = problem();
  s << "calibrated: the posterior predictive of a campaign's GP (" << emulator_->state().x_train.rows() << " samples over";
  for (const InputSpec& input : emulator_->inputs()) s << " " << input.name;
  s << ") given " << p.data().mu.size() << " measurements, " << samples().rows() << " posterior samples, discrepancy "
    << (p.discrepancy() ? "on" : "off");
  if (p.priors().discrepancy_trend_sd > 0.0) s << " with a linear trend (coefficients' SD " << p.priors().discrepancy_trend_sd << ")";
  s << "\n";
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
  for (size_t j = 0; j < record_.posterior.size(); ++j) {
    const ParameterSummary& q = record_.posterior[j];
    // in the units calibrate prints (MPa, °C), not SI
    const QuantityKind kind = static_cast<Eigen::Index>(record_.posterior.size()) == p.dimension()
                                  ? p.coordinate_kind(static_cast<Eigen::Index>(j))
                                  : QuantityKind::dimensionless;
    s << "  posterior " << q.name << ": mean " << format_human(q.mean, kind) << ", sd " << format_human_difference(q.sd, kind)
      << ", 95 % " << format_human(q.lo95, kind) << " .. " << format_human(q.hi95, kind) << " (split-R^ " << q.split_rhat
      << ", ESS " << q.effective_sample_size << ")\n";
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

// ---- the model file (/calibrated) -----------------------------------------------------------

namespace {
constexpr const char* kCalibratedGroup = "/calibrated";
const std::vector<std::string> kPosteriorColumns = {"mean", "sd", "lo95", "median", "hi95", "split_rhat", "effective_sample_size"};

std::string attribute_list(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ",") + name;
  return text;
}

std::vector<std::string> attribute_names(const std::string& text) {
  std::vector<std::string> names;
  std::string name;
  for (const char c : text + ",") {
    if (c != ',') {
      name += c;
    } else if (!name.empty()) {
      names.push_back(name);
      name.clear();
    }
  }
  return names;
}
}  // namespace

void CalibratedModel::write(h5::Writer& out) const {
  const std::string g = kCalibratedGroup;
  const CalibrationProblem& p = problem();
  out.group(g);
  out.string_attribute(g, "meaning",
                       "mu(x) = mean over posterior samples s of E[eta(x, theta_s) + delta(x) | measurements]; std the "
                       "mixture's (Kennedy & O'Hagan 2001, eq. 6); the emulator is the campaign's GP over the conditions "
                       "and the law's coefficients");
  write_input_space(out, emulator_->inputs(), g + "/emulator_inputs");
  // The posterior uses the campaign's GP exactly (its latent covariance), never a grid of it: the
  // grid is left out (2.5 of the recovery study's 2.8 MB), and an older file that has one sheds it.
  emulator_->write_group(out, g + "/emulator", GaussianProcess::GridInFile::without);
  const Measurements& data = p.data();
  out.group(g + "/measurements");
  out.strings(g + "/measurements/condition_names", data.condition_names);
  out.matrix(g + "/measurements/conditions", data.conditions);
  out.doubles(g + "/measurements/mu", data.mu);
  out.doubles(g + "/measurements/mu_sd", data.mu_sd);
  out.strings(g + "/measurements/row_names", data.row_names);
  // Conditions known within an uncertainty, and the data sets (both absent in files before them).
  out.matrix(g + "/measurements/condition_sd", data.condition_sd);
  out.matrix(g + "/measurements/condition_half_width", data.condition_half_width);
  out.strings(g + "/measurements/data_sets", data.data_sets);
  out.ints(g + "/measurements/data_set_of_row", std::vector<long long>(data.data_set_of_row.begin(), data.data_set_of_row.end()));
  out.string_attribute(g, "parameters", attribute_list(p.parameters()));
  // Held inputs: names and values (files before them held an input as a constant condition column).
  std::vector<std::string> held_names;
  std::vector<double> held_values;
  for (const auto& [name, value] : p.held()) {
    held_names.push_back(name);
    held_values.push_back(value);
  }
  out.string_attribute(g, "held", "");
  out.strings(g + "/held_inputs", held_names);
  out.doubles(g + "/held_values", held_values);
  out.int_attribute(g, "discrepancy", p.discrepancy() ? 1 : 0);
  out.double_attribute(g, "discrepancy_trend_sd", p.priors().discrepancy_trend_sd);
  // Each biased data set's name and its prior (kind, a, b): what the posterior's bias columns mean.
  std::vector<std::string> bias_sets;
  h5::RowMatrix bias_priors(static_cast<Eigen::Index>(p.priors().biases.size()), 3);
  for (size_t b = 0; b < p.priors().biases.size(); ++b) {
    const auto& [name, prior] = p.priors().biases[b];
    bias_sets.push_back(name);
    bias_priors.row(static_cast<Eigen::Index>(b)) << static_cast<double>(prior.kind), prior.a, prior.b;
  }
  out.strings(g + "/bias_sets", bias_sets);
  out.matrix(g + "/bias_priors", bias_priors);
  // The coefficients' priors as sampled (kind, a, b; a default uniform written out over its box) and
  // δ's hyper-parameters' priors: what `mufric learn` recalibrates with (absent in files before it).
  h5::RowMatrix parameter_priors(p.parameter_count(), 3);
  for (Eigen::Index k = 0; k < p.parameter_count(); ++k) {
    const Prior& prior = p.prior_of(k);
    parameter_priors.row(k) << static_cast<double>(prior.kind), prior.a, prior.b;
  }
  out.matrix(g + "/parameter_priors", parameter_priors);
  h5::RowMatrix discrepancy_priors(2, 3);
  for (const auto& [row, prior] : {std::pair{0, p.priors().discrepancy_amplitude}, std::pair{1, p.priors().discrepancy_length_scale}}) {
    discrepancy_priors.row(row) << static_cast<double>(prior.kind), prior.a, prior.b;
  }
  out.matrix(g + "/discrepancy_priors", discrepancy_priors);
  out.matrix(g + "/samples", samples());
  out.string_attribute(g, "data_source", record_.data_source);
  out.string_attribute(g, "priors", record_.priors);
  out.int_attribute(g, "walkers", record_.walkers);
  out.int_attribute(g, "steps", record_.steps);
  out.int_attribute(g, "burn_in_steps", record_.burn_in_steps);
  out.int_attribute(g, "seed", static_cast<long long>(record_.seed));
  out.double_attribute(g, "acceptance", record_.acceptance);
  std::vector<std::string> names;
  Eigen::MatrixXd table(static_cast<Eigen::Index>(record_.posterior.size()), static_cast<Eigen::Index>(kPosteriorColumns.size()));
  for (size_t j = 0; j < record_.posterior.size(); ++j) {
    const ParameterSummary& q = record_.posterior[j];
    names.push_back(q.name);
    table.row(static_cast<Eigen::Index>(j)) << q.mean, q.sd, q.lo95, q.median, q.hi95, q.split_rhat, q.effective_sample_size;
  }
  out.group(g + "/posterior");
  out.string_attribute(g + "/posterior", "columns", attribute_list(kPosteriorColumns));
  out.strings(g + "/posterior/names", names);
  out.matrix(g + "/posterior/summary", table);
  if (fast_) write_fast_evaluator(out, *fast_, g + "/fast_evaluator");
}

namespace {
// A prior stored as a row (kind, a, b) of `matrix`, checked; the reader's error names the dataset.
Prior prior_in_row(const h5::Reader& in, const std::string& dataset, const Eigen::MatrixXd& matrix, Eigen::Index row) {
  const double kind = matrix(row, 0);
  if (!(kind >= 0.0 && kind <= static_cast<double>(PriorKind::half_normal) && kind == std::floor(kind))) {
    in.fail(dataset, "an unknown prior kind");
  }
  Prior prior{static_cast<PriorKind>(static_cast<int>(kind)), matrix(row, 1), matrix(row, 2)};
  try {
    prior.check(dataset);
  } catch (const Error& e) {
    in.fail(dataset, e.what());
  }
  return prior;
}
}  // namespace

CalibratedModel CalibratedModel::read(const h5::Reader& in, InputSpace inputs) {
  const std::string g = kCalibratedGroup;
  InputSpace emulator_inputs = read_input_space(in, g + "/emulator_inputs");
  auto emulator = std::make_shared<const GaussianProcess>(GaussianProcess::read_group(in, emulator_inputs, g + "/emulator"));
  Measurements data;
  data.condition_names = in.strings(g + "/measurements/condition_names");
  data.conditions = in.matrix(g + "/measurements/conditions");
  const auto rows = data.conditions.rows();
  if (data.conditions.cols() != static_cast<Eigen::Index>(data.condition_names.size())) {
    in.fail(g + "/measurements/conditions", "has " + std::to_string(data.conditions.cols()) + " columns for " +
                                               std::to_string(data.condition_names.size()) + " condition names");
  }
  data.mu = in.vector(g + "/measurements/mu", rows);
  data.mu_sd = in.vector(g + "/measurements/mu_sd", rows);
  data.row_names = in.strings(g + "/measurements/row_names");
  if (static_cast<Eigen::Index>(data.row_names.size()) != rows) in.fail(g + "/measurements/row_names", "not one per measurement");
  if (in.has(g + "/measurements/condition_sd")) {
    data.condition_sd = in.matrix(g + "/measurements/condition_sd");
    data.condition_half_width = in.matrix(g + "/measurements/condition_half_width");
    for (const auto* m : {&data.condition_sd, &data.condition_half_width}) {
      if (m->rows() != rows || m->cols() != data.conditions.cols() || !m->allFinite() || (m->array() < 0.0).any()) {
        in.fail(g + "/measurements/condition_sd", "the conditions' uncertainties must be finite, non-negative, one per condition");
      }
    }
    data.data_sets = in.strings(g + "/measurements/data_sets");
    for (const long long k : in.ints(g + "/measurements/data_set_of_row")) {
      if (k < 0 || k >= static_cast<long long>(data.data_sets.size())) in.fail(g + "/measurements/data_set_of_row", "names no data set");
      data.data_set_of_row.push_back(static_cast<int>(k));
    }
    if (static_cast<Eigen::Index>(data.data_set_of_row.size()) != rows) in.fail(g + "/measurements/data_set_of_row", "not one per measurement");
  }
  std::vector<std::pair<std::string, double>> held;
  if (in.has(g + "/held_inputs")) {
    const std::vector<std::string> names = in.strings(g + "/held_inputs");
    const std::vector<double> values = in.doubles(g + "/held_values");
    if (names.size() != values.size()) in.fail(g + "/held_values", "not one per held input");
    for (size_t h = 0; h < names.size(); ++h) held.emplace_back(names[h], values[h]);
  }
  // Files before held inputs had their own: a constant condition column named in "held".
  for (const std::string& name : attribute_names(in.string_attribute(g, "held"))) {
    const auto found = std::find(data.condition_names.begin(), data.condition_names.end(), name);
    if (found == data.condition_names.end()) in.fail(g, "held input '" + name + "' is not among the measurements' conditions");
    const auto c = static_cast<Eigen::Index>(found - data.condition_names.begin());
    if (!(data.conditions.col(c).array() == data.conditions(0, c)).all()) in.fail(g, "held input '" + name + "' differs between rows");
    held.emplace_back(name, data.conditions(0, c));
    data.condition_names.erase(found);
    auto drop = [c](Eigen::MatrixXd& m) {
      if (m.size() == 0) return;
      Eigen::MatrixXd kept(m.rows(), m.cols() - 1);
      kept << m.leftCols(c), m.rightCols(m.cols() - c - 1);
      m = kept;
    };
    drop(data.conditions);
    drop(data.condition_sd);
    drop(data.condition_half_width);
  }
  CalibrationPriors priors;
  priors.discrepancy = in.int_attribute(g, "discrepancy") != 0;
  // Files before the trend have none.
  if (in.has_attribute(g, "discrepancy_trend_sd")) priors.discrepancy_trend_sd = in.double_attribute(g, "discrepancy_trend_sd");
  if (in.has(g + "/bias_sets")) {
    const std::vector<std::string> sets = in.strings(g + "/bias_sets");
    const Eigen::MatrixXd bias_priors = in.matrix(g + "/bias_priors");
    if (bias_priors.rows() != static_cast<Eigen::Index>(sets.size()) || (!sets.empty() && bias_priors.cols() != 3)) {
      in.fail(g + "/bias_priors", "one row (kind, a, b) per biased data set");
    }
    for (size_t b = 0; b < sets.size(); ++b) {
      priors.biases.emplace_back(sets[b], prior_in_row(in, g + "/bias_priors", bias_priors, static_cast<Eigen::Index>(b)));
    }
  }
  const std::vector<std::string> parameters = attribute_names(in.string_attribute(g, "parameters"));
  // The priors a recalibration needs (files before them served without: their posterior is fixed).
  const bool priors_kept = in.has(g + "/parameter_priors");
  if (priors_kept) {
    const Eigen::MatrixXd parameter_priors = in.matrix(g + "/parameter_priors");
    const Eigen::MatrixXd discrepancy_priors = in.matrix(g + "/discrepancy_priors");
    if (parameter_priors.rows() != static_cast<Eigen::Index>(parameters.size()) || parameter_priors.cols() != 3) {
      in.fail(g + "/parameter_priors", "one row (kind, a, b) per calibrated coefficient");
    }
    if (discrepancy_priors.rows() != 2 || discrepancy_priors.cols() != 3) in.fail(g + "/discrepancy_priors", "two rows (kind, a, b)");
    for (size_t k = 0; k < parameters.size(); ++k) {
      priors.parameters.emplace_back(parameters[k], prior_in_row(in, g + "/parameter_priors", parameter_priors, static_cast<Eigen::Index>(k)));
    }
    priors.discrepancy_amplitude = prior_in_row(in, g + "/discrepancy_priors", discrepancy_priors, 0);
    priors.discrepancy_length_scale = prior_in_row(in, g + "/discrepancy_priors", discrepancy_priors, 1);
  }
  const Eigen::MatrixXd samples = in.matrix(g + "/samples");
  auto problem = std::make_shared<const CalibrationProblem>(emulator, std::move(data), parameters, priors, held);
  if (samples.cols() != problem->dimension() || samples.rows() < 1 || !samples.allFinite()) {
    in.fail(g + "/samples", "must hold one finite row per posterior sample, " + std::to_string(problem->dimension()) + " columns");
  }
  CalibrationRecord record;
  record.data_source = in.string_attribute(g, "data_source");
  record.priors = in.string_attribute(g, "priors");
  record.walkers = static_cast<int>(in.int_attribute(g, "walkers"));
  record.steps = static_cast<int>(in.int_attribute(g, "steps"));
  record.burn_in_steps = static_cast<int>(in.int_attribute(g, "burn_in_steps"));
  record.seed = static_cast<unsigned long long>(in.int_attribute(g, "seed"));
  record.acceptance = in.double_attribute(g, "acceptance");
  record.priors_kept = priors_kept;
  const std::vector<std::string> names = in.strings(g + "/posterior/names");
  const Eigen::MatrixXd table = in.matrix(g + "/posterior/summary");
  if (table.rows() != static_cast<Eigen::Index>(names.size()) || table.cols() != static_cast<Eigen::Index>(kPosteriorColumns.size())) {
    in.fail(g + "/posterior/summary", "must have one row per name and " + std::to_string(kPosteriorColumns.size()) + " columns");
  }
  for (size_t j = 0; j < names.size(); ++j) {
    const auto r = table.row(static_cast<Eigen::Index>(j));
    record.posterior.push_back({names[j], r(0), r(1), r(2), r(4), r(3), r(5), r(6)});
  }
  CalibratedModel model(std::make_shared<const CalibratedPosterior>(std::move(problem), samples), std::move(record));
  if (!same_input_space(model.inputs(), inputs)) in.fail("/inputs", "are not the calibrated model's served inputs");
  if (in.has(g + "/fast_evaluator")) model.attach_fast_evaluator(read_fast_evaluator(in, model, g + "/fast_evaluator"));
  return model;
}


}  // namespace mufric
