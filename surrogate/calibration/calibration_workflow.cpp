#include "surrogate/calibration/calibration_workflow.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"

namespace mufric {
namespace {

bool is_law_coefficient(const std::string& input_name) {
  const KnownInput* known = find_known_input(input_name);
  return known != nullptr && !known->on_the_wire;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::vector<std::string> input_names(const GaussianProcess& model) {
  std::vector<std::string> names;
  for (const InputSpec& input : model.inputs()) names.push_back(input.name);
  return names;
}

std::string box_text(const InputSpec& input) {
  return format_human(input.lo, input.kind()) + " – " + format_human(input.hi, input.kind());
}

// --fix NAME=VALUE → (name, SI value), checked against the model's inputs and box.
std::pair<std::string, double> parse_fixed(const GaussianProcess& model, const std::string& assignment) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos) throw Error("--fix '" + assignment + "': give NAME=VALUE, e.g. adhesive_coefficient=0.35");
  const std::string name = assignment.substr(0, equals);
  if (!contains(input_names(model), name)) {
    throw Error("--fix '" + assignment + "': '" + name + "' is not an input of the model (its inputs: " +
                joined(input_names(model)) + ")");
  }
  const InputSpec& input = input_of(model, name);
  const double value = parse_quantity(assignment.substr(equals + 1), input.kind(), "--fix " + name);
  if (!input.contains(value)) {
    throw Error("--fix '" + assignment + "': " + format_human(value, input.kind()) + " is outside the model's box for " + name +
                " (" + box_text(input) + "): the emulator knows nothing there");
  }
  return {name, value};
}

// The measurement files' names as given, their content's sha256 (a path can be deleted or its file
// changed; the hash says which file it was) and their '#' provenance lines as the running text they
// are (a line break in a comment is not a sentence's end).
std::string data_source_of(const std::vector<std::string>& paths) {
  std::string source;
  for (const std::string& path : paths) {
    if (!source.empty()) source += " | ";
    const std::string content = read_whole_file(path).value_or("");
    source += path + " (sha256 " + sha256_hex(content) + ")";
    std::istringstream lines(content);
    std::string provenance;
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind('#', 0) != 0) continue;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto text = line.find_first_not_of("# ");
      if (text != std::string::npos) provenance += (provenance.empty() ? "" : " ") + line.substr(text);
    }
    if (!provenance.empty()) source += ": " + provenance;
  }
  return source;
}

// μ values that cannot be friction are refused, those no coefficient in the box can reach refused or
// warned of, identical rows warned of.
void check_plausible(const GaussianProcess& model, const Measurements& data, std::vector<std::string>& warnings) {
  const Eigen::VectorXd& computed = model.state().y_train;
  const double lowest = computed.minCoeff(), highest = computed.maxCoeff();
  char range[96];
  std::snprintf(range, sizeof range, "%.3g – %.3g", lowest, highest);
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    const std::string& row = data.row_names[static_cast<size_t>(i)];
    const double mu = data.mu(i), sd = data.mu_sd(i);
    char value[64];
    std::snprintf(value, sizeof value, "%.4g", mu);
    if (!std::isfinite(mu)) throw Error(row + ": μ is not a finite number");
    if (mu < 0.0) throw Error(row + ": μ " + value + " is negative: a friction coefficient is not (a sign convention?)");
    if (mu > kLargestPlausibleFriction) {
      throw Error(row + ": μ " + value + " cannot be a friction coefficient of a sliding contact (a percentage? a force?)");
    }
    if (!(std::isfinite(sd) && sd > 0.0)) continue;  // the problem refuses it, naming the row
    const double outside = mu < lowest ? (lowest - mu) / sd : mu > highest ? (mu - highest) / sd : 0.0;
    char sds[32];
    std::snprintf(sds, sizeof sds, "%.1f", outside);
    if (outside > kUnreachableMeasurementSds) {
      throw Error(row + ": μ " + value + " lies " + sds + " of its SDs outside every μ the campaign computed (" + range +
                  "): no coefficient in the model's box reaches it (check the value, or run the campaign over coefficients that do)");
    }
    if (outside > kSuspiciousMeasurementSds) {
      warnings.push_back(row + ": μ " + value + " lies " + sds + " of its SDs outside every μ the campaign computed (" + range +
                         "): expect the posterior at the box's edge");
    }
  }
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    for (Eigen::Index j = i + 1; j < data.rows(); ++j) {
      if (data.mu(i) == data.mu(j) && data.mu_sd(i) == data.mu_sd(j) && data.conditions.row(i) == data.conditions.row(j)) {
        warnings.push_back(data.row_names[static_cast<size_t>(i)] + " and " + data.row_names[static_cast<size_t>(j)] +
                           " are identical: each counts as a measurement of its own and narrows the posterior "
                           "(leave one out if it is a copy)");
      }
    }
  }
}

// A prior's share inside the box: none is an error, less than half a warning.
void check_prior_mass(const Prior& prior, const InputSpec& input, const std::string& what, std::vector<std::string>& warnings) {
  const double inside = prior.mass_within(input.lo, input.hi);
  if (inside <= 0.0) {
    throw Error(what + ": its prior " + prior.describe(input.kind()) + " lies wholly outside the model's box " +
                box_text(input) + " (the emulator knows nothing there)");
  }
  if (inside < kLeastPriorMassInsideBox) {
    char share[32];
    std::snprintf(share, sizeof share, "%.0f %%", 100.0 * inside);
    warnings.push_back(what + ": only " + std::string(share) + " of its prior " + prior.describe(input.kind()) +
                       " lies inside the model's box " + box_text(input) +
                       "; the rest is cut away and the posterior may pile at the box's edge");
  }
}

}  // namespace

CalibrationSetup prepare_calibration(std::shared_ptr<const GaussianProcess> emulator, const CalibrationRequest& request) {
  const GaussianProcess& model = *emulator;
  const std::vector<std::string> inputs = input_names(model);
  std::vector<std::string> coefficients;
  for (const std::string& name : inputs) {
    if (is_law_coefficient(name)) coefficients.push_back(name);
  }
  if (coefficients.empty()) {
    throw Error("--model: this model has no law coefficient to calibrate (its inputs: " + joined(inputs) +
                "): calibrate needs the GP of a campaign that varied one, e.g. `dataset plan --shear-factor 0.2:0.9 "
                "--set contact.law=childs`, run and trained");
  }
  if (request.data_files.empty()) throw Error("--data: no measurements given");
  std::vector<Measurements> sets;
  for (const std::string& path : request.data_files) sets.push_back(read_measurements(path));
  Measurements data = combine_measurement_sets(sets);

  std::vector<std::pair<std::string, double>> held;
  for (const std::string& assignment : request.fixed) {
    const auto fixed = parse_fixed(model, assignment);
    if (contains(data.condition_names, fixed.first)) {
      throw Error("--fix '" + assignment + "': the measurements already give " + fixed.first);
    }
    for (const auto& [name, value] : held) {
      if (name == fixed.first) throw Error("--fix '" + assignment + "': " + name + " is fixed twice");
    }
    held.push_back(fixed);
  }
  auto is_held = [&held](const std::string& name) {
    return std::any_of(held.begin(), held.end(), [&name](const auto& h) { return h.first == name; });
  };
  for (const std::string& name : data.condition_names) {
    if (!contains(inputs, name)) {
      throw Error(request.data_files.front() + ": the measurements give " + name + ", which is not an input of the model (its inputs: " +
                  joined(inputs) + ")");
    }
  }
  // Every condition of the model (an input on the wire) comes from the data or is held.
  for (const std::string& name : inputs) {
    if (is_law_coefficient(name) || contains(data.condition_names, name) || is_held(name)) continue;
    const std::string unit(human_unit(kind_of_input(name)));
    const std::string column = name + "[" + (unit.empty() ? "1" : unit) + "]";
    throw Error("the measurements give no " + name + ", a condition of the model: add a column " + column + " (with " + name +
                "_sd for its uncertainty, or " + name + "_min and " + name + "_max for a range), or hold it with --fix " + name +
                "=VALUE (a forgotten condition would otherwise be calibrated as if it were a coefficient)");
  }
  std::vector<std::string> parameters = request.calibrated;
  if (parameters.empty()) {
    for (const std::string& name : coefficients) {
      if (!contains(data.condition_names, name) && !is_held(name)) parameters.push_back(name);
    }
    if (parameters.empty()) {
      throw Error("every law coefficient of the model (" + joined(coefficients) + ") is fixed or measured: nothing to calibrate");
    }
  }
  for (const std::string& name : parameters) {
    if (!contains(inputs, name)) {
      throw Error("--calibrate " + name + ": not an input of the model (its law coefficients: " + joined(coefficients) + ")");
    }
    if (!is_law_coefficient(name)) {
      throw Error("--calibrate " + name + ": a condition of the measurements, not a law coefficient: give it in the data (with " +
                  name + "_sd for its uncertainty) or --fix it");
    }
    if (contains(data.condition_names, name) || is_held(name)) {
      throw Error("--calibrate " + name + ": the measurements give it or --fix holds it");
    }
  }
  for (const std::string& name : coefficients) {
    if (!contains(parameters, name) && !contains(data.condition_names, name) && !is_held(name)) {
      throw Error("the law coefficient " + name + " is neither calibrated nor fixed: add it to --calibrate or --fix " + name + "=VALUE");
    }
  }

  CalibrationPriors priors;
  if (!request.priors_file.empty()) {
    const std::optional<std::string> text = read_whole_file(request.priors_file);
    if (!text) throw Error("--priors " + request.priors_file + ": cannot be read");
    priors = parse_calibration_priors(*text, request.priors_file);
  }
  if (request.discrepancy) priors.discrepancy = true;
  if (request.discrepancy_trend_sd) priors.discrepancy_trend_sd = *request.discrepancy_trend_sd;

  CalibrationSetup setup;
  check_plausible(model, completed(data), setup.warnings);
  for (const auto& [name, prior] : priors.parameters) {
    if (contains(parameters, name)) check_prior_mass(prior, input_of(model, name), "prior of " + name, setup.warnings);
  }
  const Measurements complete = completed(data);
  for (Eigen::Index i = 0; i < complete.rows(); ++i) {
    for (Eigen::Index c = 0; c < complete.conditions.cols(); ++c) {
      if (!complete.uncertain(i, c)) continue;
      const std::string& name = complete.condition_names[static_cast<size_t>(c)];
      const InputSpec& input = input_of(model, name);
      const Prior prior = complete.condition_prior(i, c);
      if (prior.mass_within(input.lo, input.hi) > 0.0) {
        check_prior_mass(prior, input, complete.row_names[static_cast<size_t>(i)] + ", " + name, setup.warnings);
      }
    }
  }
  if (priors.discrepancy && complete.rows() <= kRowsTheDiscrepancyExplainsAlone) {
    setup.warnings.push_back("with the discrepancy on, " + count_of(complete.rows(), "measurement", "measurements") +
                             " cannot tell δ from the law: δ may explain it alone, and what the posterior says of the "
                             "coefficients comes from δ's amplitude prior (" + priors.discrepancy_amplitude.describe() +
                             "); give more rows, or calibrate without --discrepancy");
  }
  setup.problem = std::make_shared<const CalibrationProblem>(std::move(emulator), std::move(data), parameters, priors, held);
  setup.data_source = data_source_of(request.data_files);
  return setup;
}

CalibrationSetup recalibration_setup(const CalibratedModel& model, std::shared_ptr<const GaussianProcess> emulator) {
  if (!model.record().priors_kept) {
    throw Error("the calibrated model's file predates kept priors, so its calibration cannot be run again: calibrate it "
                "once more with mufric calibrate (its record: priors " + model.record().priors + ")");
  }
  if (input_names(*emulator) != input_names(model.emulator())) {
    throw Error("recalibration: the new emulator's inputs (" + joined(input_names(*emulator)) + ") are not the calibrated model's (" +
                joined(input_names(model.emulator())) + ")");
  }
  const CalibrationProblem& old = model.problem();
  CalibrationSetup setup;
  setup.problem = std::make_shared<const CalibrationProblem>(std::move(emulator), old.data(), old.parameters(), old.priors(), old.held());
  setup.data_source = model.record().data_source;
  return setup;
}

CalibrationRecord calibration_record(const CalibrationSetup& setup, const CalibrationResult& result) {
  const CalibrationProblem& problem = *setup.problem;
  std::string priors;
  for (Eigen::Index k = 0; k < problem.parameter_count(); ++k) {
    const std::string& name = problem.parameters()[static_cast<size_t>(k)];
    priors += (k ? "; " : "") + name + " " + problem.prior_of(k).describe(kind_of_input(name));
  }
  const CalibrationPriors& p = problem.priors();
  if (p.discrepancy) {
    priors += "; discrepancy_amplitude " + p.discrepancy_amplitude.describe() + "; discrepancy_length_scale " +
              p.discrepancy_length_scale.describe();
    if (p.discrepancy_trend_sd > 0.0) priors += "; discrepancy trend " + Prior{PriorKind::normal, 0.0, p.discrepancy_trend_sd}.describe() + " coefficients";
  }
  for (const auto& [set, prior] : p.biases) priors += "; bias[" + set + "] " + prior.describe();
  if (problem.latent_count() > 0) {
    priors += "; " + std::to_string(problem.latent_count()) + " uncertain conditions: their stated SDs or ranges, cut to the box";
  }
  return CalibrationRecord{.data_source = setup.data_source,
                           .priors = priors,
                           .posterior = result.summary,
                           .walkers = result.options.walkers,
                           .steps = result.options.steps,
                           .burn_in_steps = result.options.burn_in_steps,
                           .seed = static_cast<unsigned long long>(result.options.seed),
                           .acceptance = result.acceptance};
}

CalibratedModel calibrated_model(const CalibrationSetup& setup, const CalibrationResult& result) {
  CalibratedModel model(std::make_shared<const CalibratedPosterior>(setup.problem, result.samples), calibration_record(setup, result));
  model.set_default_extrapolation(setup.problem->emulator().default_extrapolation());
  model.set_mu_range(setup.problem->emulator().mu_min(), setup.problem->emulator().mu_max());
  return model;
}

}  // namespace mufric
