// `mufric calibrate`: the posterior of an interface law's coefficients given measured friction,
// through the GP of a campaign that varied them (surrogate/calibration.hpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
#include "surrogate/calibrated_model.hpp"
#include "surrogate/calibration.hpp"
#include "surrogate/fast_evaluator_build.hpp"
#include "surrogate/model_file.hpp"

namespace mufric::app {
namespace {

struct CalibrateOptions {
  std::string model, data, priors, out, model_out;
  // The tolerances a request asks by default (EvaluationRequest), so that the grid answers it.
  double fast_mu_tolerance = EvaluationRequest{}.mu_tolerance, fast_std_tolerance = EvaluationRequest{}.std_relative_tolerance;
  // The grid's work budget in the GP's multiply-adds (CalibratedModel::exact_point_work): about 5
  // minutes of one core (1e10 per second).
  double fast_max_gigawork = 3000.0;
  bool no_fast_evaluator = false;
  std::vector<std::string> parameters, fixed;
  bool discrepancy = false;
  EnsembleOptions sampler;
};

std::shared_ptr<const GaussianProcess> load_emulator(const std::string& path) {
  std::unique_ptr<FrictionModel> model = load_model_isolated(model_path_from_uri(path));
  auto* gp = dynamic_cast<GaussianProcess*>(model.get());
  if (gp == nullptr) {
    throw Error("--model " + path + ": a calibration needs a Gaussian-process model of a campaign (this one is '" +
                std::string(model->kind()) + "')");
  }
  model.release();
  return std::shared_ptr<const GaussianProcess>(gp);
}

// --fix NAME=VALUE: the input held at one value, as a condition every measurement shares; its name.
std::string fix_input(Measurements& data, const std::string& assignment) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos) throw Error("--fix '" + assignment + "': give NAME=VALUE, e.g. adhesive_coefficient=0.35");
  const std::string name = assignment.substr(0, equals);
  const KnownInput* known = find_known_input(name);
  if (known == nullptr) throw Error("--fix '" + assignment + "': '" + name + "' is not a model input");
  if (std::find(data.condition_names.begin(), data.condition_names.end(), name) != data.condition_names.end()) {
    throw Error("--fix '" + assignment + "': the measurements already give " + name);
  }
  const double value = parse_quantity(assignment.substr(equals + 1), known->kind, "--fix " + name);
  data.condition_names.push_back(name);
  data.conditions.conservativeResize(Eigen::NoChange, data.conditions.cols() + 1);
  data.conditions.col(data.conditions.cols() - 1).setConstant(value);
  return name;
}

// Every input of the model that the measurements do not give.
std::vector<std::string> unmeasured_inputs(const GaussianProcess& model, const Measurements& data) {
  std::vector<std::string> names;
  for (const InputSpec& input : model.inputs()) {
    if (std::find(data.condition_names.begin(), data.condition_names.end(), input.name) == data.condition_names.end()) {
      names.push_back(input.name);
    }
  }
  return names;
}

void print_summary(const CalibrationProblem& problem, const CalibrationResult& result, double seconds) {
  std::printf("%-26s %10s %10s %23s %8s %8s\n", "parameter", "mean", "sd", "95 % credible interval", "split-R^", "ESS");
  for (const ParameterSummary& s : result.summary) {
    char interval[64];
    std::snprintf(interval, sizeof interval, "%.4g .. %.4g", s.lo95, s.hi95);
    std::printf("%-26s %10.4g %10.4g %23s %8.3f %8.0f\n", s.name.c_str(), s.mean, s.sd, interval, s.split_rhat,
                s.effective_sample_size);
  }
  std::printf("%d walkers x %d steps after %d burn-in, seed %llu; acceptance %.2f; %.1f s\n", result.options.walkers,
              result.options.steps, result.options.burn_in_steps, static_cast<unsigned long long>(result.options.seed),
              result.acceptance, seconds);
  if (problem.discrepancy()) {
    std::printf("discrepancy_amplitude in mu units, discrepancy_length_scale in widths of the model's box\n");
  }
}

void write_posterior(const std::string& path, const CalibrationProblem& problem, const CalibrationResult& result,
                     const CalibrateOptions& o) {
  std::ostringstream text;
  text << "# posterior samples of mufric calibrate (every walker's kept states, natural units)\n";
  text << "# model " << o.model << ", measurements " << o.data << (o.priors.empty() ? "" : ", priors " + o.priors)
       << ", seed " << o.sampler.seed << "\n";
  const auto& names = problem.coordinate_names();
  for (size_t j = 0; j < names.size(); ++j) text << (j ? "," : "") << names[j];
  text << "\n";
  char number[32];
  for (Eigen::Index i = 0; i < result.samples.rows(); ++i) {
    for (Eigen::Index j = 0; j < result.samples.cols(); ++j) {
      std::snprintf(number, sizeof number, "%.17g", result.samples(i, j));
      text << (j ? "," : "") << number;
    }
    text << "\n";
  }
  write_file_atomically(path, text.str());
}

// The measurement file's name and its '#' provenance lines, for the calibrated model's record.
std::string measurement_source(const std::string& path) {
  std::string source = path;
  std::istringstream lines(read_whole_file(path).value_or(""));
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind('#', 0) == 0) source += "; " + line.substr(line.find_first_not_of("# ") == std::string::npos ? line.size() : line.find_first_not_of("# "));
  }
  return source;
}

std::string priors_text(const CalibrationProblem& problem, const CalibrationPriors& priors) {
  std::string text;
  for (Eigen::Index k = 0; k < problem.parameter_count(); ++k) {
    text += (k ? "; " : "") + problem.coordinate_names()[static_cast<size_t>(k)] + " " + problem.prior_of(k).describe();
  }
  if (priors.discrepancy) {
    text += "; discrepancy_amplitude " + priors.discrepancy_amplitude.describe() + "; discrepancy_length_scale " +
            priors.discrepancy_length_scale.describe();
  }
  return text;
}

// The calibrated model: served like any other, with a fast evaluator certified against it.
void write_calibrated_model(const CalibrateOptions& o, const std::shared_ptr<const GaussianProcess>& emulator,
                            const Measurements& data, const std::vector<std::string>& parameters,
                            const std::vector<std::string>& held,
                            const CalibrationProblem& problem, const CalibrationPriors& priors, const CalibrationResult& result) {
  CalibrationRecord record{.data_source = measurement_source(o.data),
                           .priors = priors_text(problem, priors),
                           .posterior = result.summary,
                           .walkers = o.sampler.walkers,
                           .steps = o.sampler.steps,
                           .burn_in_steps = o.sampler.burn_in_steps,
                           .seed = static_cast<unsigned long long>(o.sampler.seed),
                           .acceptance = result.acceptance};
  CalibratedModel model(emulator, data, parameters, held, priors.discrepancy, result.samples, std::move(record));
  model.set_default_extrapolation(emulator->default_extrapolation());
  model.set_mu_range(emulator->mu_min(), emulator->mu_max());
  FastEvaluatorOptions fast;
  fast.mu_tolerance = o.fast_mu_tolerance;
  fast.std_relative_tolerance = o.fast_std_tolerance;
  fast.max_work = o.fast_max_gigawork * 1e9;
  fast.progress = [](const std::string& line) { std::fprintf(stderr, "calibrate: fast evaluator: %s\n", line.c_str()); };
  try {
    if (o.no_fast_evaluator) throw FastEvaluatorOverCap("--no-fast-evaluator");
    std::fprintf(stderr, "calibrate: fast evaluator: building within %.3g G multiply-adds (--fast-max-work; %.3g M a point)\n",
                 o.fast_max_gigawork, model.exact_point_work() / 1e6);
    model.attach_fast_evaluator(std::make_shared<const FastEvaluator>(
        build_fast_evaluator(GridSource{model, model.unit_length_scales(), model.exact_point_work()}, fast)));
    if (!model.fast_evaluator()->stop_reason().empty()) {
      std::printf("fast evaluator stopped before the tolerances (%s): requests asking for more use the exact model\n",
                  model.fast_evaluator()->stop_reason().c_str());
    }
  } catch (const FastEvaluatorOverCap& e) {
    std::printf("no fast evaluator (%s): the exact posterior predictive answers\n", e.what());
  }
  save_model(o.model_out, model);
  const IntervalParts& c = model.centre_parts();
  std::printf("wrote %s (calibrated model of", o.model_out.c_str());
  for (const InputSpec& input : model.inputs()) std::printf(" %s", input.name.c_str());
  std::printf(")\nat the box centre: mu %.4g, sd %.3g = sqrt(law coefficients %.3g^2 + given them %.3g^2); "
              "alone: roughness mean %.3g, discrepancy %.3g\n",
              c.mu, c.sd, c.parameter_sd, c.conditional_sd, c.emulator_sd, c.discrepancy_sd);
}

void calibrate_command(const CalibrateOptions& o) {
  const auto emulator = load_emulator(o.model);
  Measurements data = read_measurements(o.data);
  std::vector<std::string> held;
  for (const std::string& assignment : o.fixed) held.push_back(fix_input(data, assignment));
  CalibrationPriors priors;
  if (!o.priors.empty()) {
    const std::optional<std::string> text = read_whole_file(o.priors);
    if (!text) throw Error("--priors " + o.priors + ": cannot be read");
    priors = parse_calibration_priors(*text, o.priors);
  }
  if (o.discrepancy) priors.discrepancy = true;
  const std::vector<std::string> parameters = o.parameters.empty() ? unmeasured_inputs(*emulator, data) : o.parameters;
  const CalibrationProblem problem(emulator, data, parameters, priors);
  std::printf("calibrating %zu coefficient(s) against %lld measurements (%s), discrepancy %s\n", parameters.size(),
              static_cast<long long>(data.mu.size()), o.data.c_str(), priors.discrepancy ? "on" : "off");
  for (Eigen::Index k = 0; k < problem.parameter_count(); ++k) {
    std::printf("  prior of %s: %s\n", parameters[static_cast<size_t>(k)].c_str(), problem.prior_of(k).describe().c_str());
  }
  std::fflush(stdout);
  const auto started = std::chrono::steady_clock::now();
  int reported = 0;
  const CalibrationResult result = calibrate(problem, o.sampler, [&reported](int done, int total) {
    const int tenth = done * 10 / total;
    if (tenth > reported) {
      reported = tenth;
      std::fprintf(stderr, "calibrate: %d %% of the steps (%d of %d)\n", tenth * 10, done, total);
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  print_summary(problem, result, seconds);
  if (!result.convergence_failure.empty()) {
    throw Error("the posterior is not usable, nothing written: " + result.convergence_failure);
  }
  if (!o.out.empty()) {
    write_posterior(o.out, problem, result, o);
    std::printf("wrote %s (%lld samples)\n", o.out.c_str(), static_cast<long long>(result.samples.rows()));
  }
  if (!o.model_out.empty()) write_calibrated_model(o, emulator, data, parameters, held, problem, priors, result);
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto o = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand(
      "calibrate", "Posterior of the interface law's coefficients given measured friction, through a campaign's GP");
  cmd->add_option("--model", o->model,
                  "GP model of a campaign whose inputs are the measurements' conditions and the law's coefficients\n"
                  "(a plan with e.g. --shear-factor 0.2:0.9, run and trained)")
      ->required();
  cmd->add_option("--data", o->data,
                  "Measurements: CSV with the conditions as columns with units, mu and mu_sd (the measurement's\n"
                  "standard deviation), e.g. contact_pressure[MPa],sliding_velocity[m/min],mu,mu_sd")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--calibrate", o->parameters,
                  "The model inputs to calibrate (default: every input the measurements do not give)")
      ->delimiter(',');
  cmd->add_option("--fix", o->fixed,
                  "Hold a model input at one value instead of calibrating it, e.g. --fix adhesive_coefficient=0.35\n"
                  "(repeatable; for coefficients the data cannot tell apart, which calibrate refuses to sample)");
  cmd->add_option("--priors", o->priors,
                  "Priors (JSON): {\"parameters\": {\"shear_factor\": {\"uniform\": [0.2, 0.9]}},\n"
                  "\"discrepancy\": {\"enabled\": true, \"amplitude\": {\"half_normal\": [0.05]}, \"length_scale\":\n"
                  "{\"log_normal\": [0.5, 0.7]}}}; priors: uniform [lo, hi], normal [mean, sd], log_normal [median,\n"
                  "sd of log], half_normal [scale]. Default: uniform over the model's box, no discrepancy")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--discrepancy", o->discrepancy,
                "Add the model discrepancy delta(x), a zero-mean GP over the conditions (Kennedy & O'Hagan 2001)");
  cmd->add_option("--walkers", o->sampler.walkers, "Ensemble walkers (Goodman & Weare 2010)")
      ->capture_default_str()
      ->check(CLI::Range(4, 100000));
  cmd->add_option("--burn-in", o->sampler.burn_in_steps, "Steps discarded")->capture_default_str()->check(CLI::Range(0, 10000000));
  cmd->add_option("--steps", o->sampler.steps, "Steps kept")->capture_default_str()->check(CLI::Range(4, 10000000));
  cmd->add_option("--seed", o->sampler.seed, "Seed: the same seed, data and model give the same posterior, bit for bit")
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Write the posterior samples here (CSV, one column per parameter)");
  cmd->add_option("--model-out", o->model_out,
                  "Write the calibrated model here (HDF5): mu(conditions) as the posterior predictive, its interval the\n"
                  "roughness mean, the coefficients' posterior and delta; served, described and evaluated like any model");
  cmd->add_option("--fast-mu-tolerance", o->fast_mu_tolerance,
                  "The calibrated model's fast evaluator: mu within this (absolute)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--fast-std-tolerance", o->fast_std_tolerance,
                  "The calibrated model's fast evaluator: std within this (relative)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--fast-max-work", o->fast_max_gigawork,
                  "The grid's work budget, G multiply-adds of the exact GP (about 10 per second on one core); a grid\n"
                  "that does not meet the tolerances within it is kept with its certified bound, and requests asking\n"
                  "for more use the exact predictive")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--no-fast-evaluator", o->no_fast_evaluator,
                "Write the calibrated model without its grid: the exact posterior predictive answers every request\n"
                "(slower per point; the grid takes seconds to minutes to certify)");
  cmd->footer(
      "y_i = mu(x_i, theta) + delta(x_i) + eps_i: the GP's interval of the mean, the measurement's SD and\n"
      "(with --discrepancy) delta in the likelihood. Prints each parameter's mean, SD, 95 % credible interval,\n"
      "split-R^ and effective sample size; exit status 2, naming the parameter and the cause, when the chains\n"
      "fail the limits (split-R^ <= 1.05, ESS >= 400, steps >= 20 autocorrelation times), or a measurement\n"
      "lies outside the model's box (naming its line).");
  cmd->callback([o] { calibrate_command(*o); });
}

}  // namespace mufric::app
