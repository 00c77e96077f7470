// `mufric calibrate`: the posterior of an interface law's coefficients given measured friction,
// through the GP of a campaign that varied them (surrogate/calibration/calibration.hpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/fast_evaluator_options.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"
#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/calibration/calibration.hpp"
#include "surrogate/calibration/calibration_workflow.hpp"
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric::app {
namespace {

constexpr long long kDefaultPosteriorRows = 4000;

struct CalibrateOptions {
  std::string model, out, model_out;
  CalibrationRequest request;
  FastOptions fast;  // the calibrated model's grid
  EnsembleOptions sampler = [] {
    EnsembleOptions o;
    o.max_steps = kDefaultCalibrationMaxSteps;
    return o;
  }();
  bool automatic_walkers = true;  // --walkers not given: at least four per coordinate
  // --out's rows: evenly thinned to about this many (a long chain of many coordinates is tens of MB;
  // a few thousand samples draw any histogram), 0 for every kept state.
  long long out_samples = kDefaultPosteriorRows;
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

void print_summary(const CalibrationProblem& problem, const CalibrationResult& result, double seconds) {
  std::printf("%-40s %12s %12s %27s %9s %7s\n", "parameter", "mean", "sd", "95 % credible interval", "split-R^", "ESS");
  for (size_t j = 0; j < result.summary.size(); ++j) {
    const ParameterSummary& s = result.summary[j];
    const QuantityKind kind = problem.coordinate_kind(static_cast<Eigen::Index>(j));
    const std::string interval = format_human(s.lo95, kind) + " .. " + format_human(s.hi95, kind);
    std::printf("%-40s %12s %12s %27s %9.4f %7.0f\n", s.name.c_str(), format_human(s.mean, kind).c_str(),
                format_human_difference(s.sd, kind).c_str(), interval.c_str(), s.split_rhat, s.effective_sample_size);
  }
  std::printf("%d walkers x %d steps after %d burn-in, seed %llu; acceptance %.2f; %.1f s\n", result.options.walkers,
              result.options.steps, result.options.burn_in_steps, static_cast<unsigned long long>(result.options.seed),
              result.acceptance, seconds);
  std::printf("how to read it: split-R^ compares each walker's two halves and the walkers with each other (1 when they agree; "
              "used only at <= %.2f); ESS is the number of independent samples the chains are worth (used only at >= %.0f); "
              "acceptance is the share of proposed moves taken (0.2-0.5 is usual for this sampler; near 0, the walkers are stuck)\n",
              kMaximumSplitRhat, kMinimumEffectiveSamples);
  if (problem.discrepancy()) {
    std::printf("discrepancy_amplitude in mu units, discrepancy_length_scale in widths of the model's box\n");
  }
  if (problem.bias_count() > 0) std::printf("bias[set]: what that data set measures above the others, mu units\n");
  if (problem.latent_count() > 0) {
    std::printf("the rows' conditions given with an uncertainty: what the data imply of them (their prior: the stated SD or range)\n");
  }
}

// Every how many kept states --out writes one.
long long posterior_stride(long long kept, long long out_samples) {
  return out_samples > 0 ? std::max(1LL, (kept + out_samples - 1) / out_samples) : 1;
}

// Writes --out and returns how many samples it holds.
long long write_posterior(const std::string& path, const CalibrationProblem& problem, const CalibrationResult& result,
                          const CalibrateOptions& o) {
  std::ostringstream text;
  const Eigen::Index kept = result.samples.rows();
  const Eigen::Index stride = posterior_stride(kept, o.out_samples);
  text << "# posterior samples of mufric calibrate (natural units: SI for inputs and conditions): "
       << (stride == 1 ? "every walker's kept states, " + std::to_string(kept)
                       : "every " + std::to_string(stride) + "th of the walkers' " + std::to_string(kept) +
                             " kept states (--out-samples 0 for all)")
       << "\n";
  text << "# model " << o.model << ", measurements";
  for (const std::string& data : o.request.data_files) text << " " << data;
  text << (o.request.priors_file.empty() ? "" : ", priors " + o.request.priors_file) << ", seed " << o.sampler.seed << "\n";
  const auto& names = problem.coordinate_names();
  for (size_t j = 0; j < names.size(); ++j) text << (j ? "," : "") << names[j];
  text << "\n";
  char number[32];
  for (Eigen::Index i = 0; i < kept; i += stride) {
    for (Eigen::Index j = 0; j < result.samples.cols(); ++j) {
      std::snprintf(number, sizeof number, "%.17g", result.samples(i, j));
      text << (j ? "," : "") << number;
    }
    text << "\n";
  }
  write_file_atomically(path, text.str());
  return (kept + stride - 1) / stride;
}

// The calibrated model: served like any other, with a fast evaluator certified against it.
void write_calibrated_model(const CalibrateOptions& o, const CalibrationSetup& setup, const CalibrationResult& result) {
  CalibratedModel model = calibrated_model(setup, result);
  attach_fast_evaluator(model, o.fast);
  if (o.fast.skip) std::printf("no fast evaluator (--no-fast-evaluator): the exact posterior predictive answers\n");
  save_model(o.model_out, model);
  const IntervalParts& c = model.centre_parts();
  std::printf("wrote %s (calibrated model of", o.model_out.c_str());
  for (const InputSpec& input : model.inputs()) std::printf(" %s", input.name.c_str());
  std::printf(")\nat the box centre: mu %.4g, sd %.3g = sqrt(law coefficients %.3g^2 + given them %.3g^2); "
              "alone: roughness mean %.3g, discrepancy %.3g (parts alone need not add up: given the data, what one "
              "explains the other need not)\n",
              c.mu, c.sd, c.parameter_sd, c.conditional_sd, c.emulator_sd, c.discrepancy_sd);
}

void calibrate_command(const CalibrateOptions& o) {
  const CalibrationSetup setup = prepare_calibration(load_emulator(o.model), o.request);
  const CalibrationProblem& problem = *setup.problem;
  for (const std::string& warning : setup.warnings) std::printf("warning: %s\n", warning.c_str());
  std::printf("calibrating %s against %s in %s, discrepancy %s",
              count_of(problem.parameter_count(), "coefficient", "coefficients").c_str(),
              count_of(problem.data().rows(), "measurement", "measurements").c_str(),
              count_of(static_cast<long long>(problem.data().data_sets.size()), "data set", "data sets").c_str(),
              problem.discrepancy() ? "on" : "off");
  if (problem.priors().discrepancy_trend_sd > 0.0) {
    std::printf(" with a linear trend (its coefficients normal(0, %g))", problem.priors().discrepancy_trend_sd);
  }
  if (problem.latent_count() > 0) {
    std::printf(", %lld conditions with their uncertainty", static_cast<long long>(problem.latent_count()));
  }
  std::printf("\n");
  for (Eigen::Index k = 0; k < problem.parameter_count(); ++k) {
    const std::string& name = problem.parameters()[static_cast<size_t>(k)];
    std::printf("  prior of %s: %s\n", name.c_str(), problem.prior_of(k).describe(kind_of_input(name)).c_str());
  }
  for (const auto& [name, value] : problem.held()) {
    std::printf("  held: %s = %s\n", name.c_str(), format_human(value, kind_of_input(name)).c_str());
  }
  for (const auto& [set, prior] : problem.priors().biases) {
    std::printf("  bias of data set %s: %s\n", set.c_str(), prior.describe().c_str());
  }
  std::fflush(stdout);
  EnsembleOptions sampler = o.sampler;
  // Walkers: four per coordinate (the stretch move needs more than two, and mixes better with more).
  if (o.automatic_walkers) sampler.walkers = std::max(sampler.walkers, static_cast<int>(4 * problem.dimension()));
  if (sampler.walkers < 2 * problem.dimension() + 2) {
    throw Error("--walkers " + std::to_string(sampler.walkers) + ": the posterior has " + std::to_string(problem.dimension()) +
                " coordinates; give at least " + std::to_string(2 * problem.dimension() + 2) + " walkers");
  }
  const auto started = std::chrono::steady_clock::now();
  int reported = 0, run = 0;
  const CalibrationResult result = calibrate(problem, sampler, [&](int done, int total) {
    if (done == 1) {
      reported = 0;
      if (run++ > 0) std::fprintf(stderr, "calibrate: not yet within the limits: running on for %d steps\n", total);
    }
    const int tenth = done * 10 / total;
    if (tenth > reported) {
      reported = tenth;
      std::fprintf(stderr, "calibrate: %d %% of the steps (%d of %d)\n", tenth * 10, done, total);
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  print_summary(problem, result, seconds);
  for (const std::string& warning : posterior_warnings(problem, result)) std::printf("warning: %s\n", warning.c_str());
  std::fflush(stdout);
  if (!result.convergence_failure.empty()) {
    throw Error("the posterior is not usable, nothing written: " + result.convergence_failure);
  }
  if (!o.out.empty()) {
    const long long kept = result.samples.rows();
    const long long written = write_posterior(o.out, problem, result, o);
    std::printf("wrote %s (%lld of %lld kept samples%s)\n", o.out.c_str(), written, kept,
                written < kept ? ", evenly thinned; --out-samples 0 for all" : "");
  }
  if (!o.model_out.empty()) write_calibrated_model(o, setup, result);
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
  cmd->add_option("--data", o->request.data_files,
                  "Measurements: CSV with the conditions as columns with units, mu and mu_sd (the measurement's\n"
                  "standard deviation), e.g. contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu,mu_sd;\n"
                  "a condition known only within an uncertainty adds temperature_sd[C] (normal) or temperature_min[C]\n"
                  "and temperature_max[C] (a range). Repeatable: each file is a data set (named by its stem), which the\n"
                  "priors file may give a bias of its own (\"data_sets\": {\"NAME\": {\"bias\": {\"normal\": [0, 0.1]}}})")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--calibrate", o->request.calibrated,
                  "The law coefficients to calibrate (default: every coefficient of the model the measurements do not\n"
                  "give and --fix does not hold; a condition the measurements lack is an error, not calibrated)")
      ->delimiter(',');
  cmd->add_option("--fix", o->request.fixed,
                  "Hold a model input at one value instead of calibrating it, e.g. --fix adhesive_coefficient=0.35\n"
                  "(repeatable; for coefficients the data cannot tell apart, which calibrate refuses to sample)");
  cmd->add_option("--priors", o->request.priors_file,
                  "Priors (JSON): {\"parameters\": {\"shear_factor\": {\"uniform\": [0.2, 0.9]}},\n"
                  "\"discrepancy\": {\"enabled\": true, \"amplitude\": {\"half_normal\": [0.05]}, \"length_scale\":\n"
                  "{\"log_normal\": [0.5, 0.7]}}, \"data_sets\": {\"tribometer\": {\"bias\": {\"normal\": [0, 0.1]}}}};\n"
                  "priors: uniform [lo, hi], normal [mean, sd], log_normal [median, sd of log], half_normal [scale], in SI.\n"
                  "Default: uniform over the model's box, no discrepancy, no bias")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--discrepancy", o->request.discrepancy,
                "Add the model discrepancy delta(x), a zero-mean GP over the conditions (Kennedy & O'Hagan 2001)");
  cmd->add_option("--discrepancy-trend", o->request.discrepancy_trend_sd,
                  "With --discrepancy: delta also carries a linear trend over the conditions, an offset and a slope per\n"
                  "input whose coefficients are normal(0, SD) in mu units per width of the model's box (KOH 2001 §4.3's\n"
                  "regression mean, integrated out). For a model that misses a trend the measurements show (the Ti6Al4V\n"
                  "model ships with 0.15): it sharpens the prediction and widens the coefficients' posterior (the trend\n"
                  "can stand in for them); to read the coefficients themselves, calibrate without it. Default: none")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--walkers", o->sampler.walkers,
                  "Ensemble walkers (Goodman & Weare 2010); default: 32, or four per posterior coordinate when more")
      ->check(CLI::Range(4, 100000))
      ->each([o](const std::string&) { o->automatic_walkers = false; });
  cmd->add_option("--burn-in", o->sampler.burn_in_steps, "Steps discarded")->capture_default_str()->check(CLI::Range(0, 10000000));
  cmd->add_option("--steps", o->sampler.steps, "Steps kept")->capture_default_str()->check(CLI::Range(4, 10000000));
  cmd->add_option("--max-steps", o->sampler.max_steps,
                  "A run not yet within the limits goes on, its length doubling, up to this many steps in all, and is\n"
                  "judged on its latest run (0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000000));
  cmd->add_option("--seed", o->sampler.seed, "Seed: the same seed, data and model give the same posterior, bit for bit")
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Write the posterior samples here (CSV, one column per parameter)");
  cmd->add_option("--out-samples", o->out_samples,
                  "--out's rows: the kept samples evenly thinned to at most this many (0: every kept state, which for\n"
                  "many coordinates and a long chain is tens of MB)")
      ->capture_default_str()
      ->check(CLI::Range(0LL, 1000000000LL));
  cmd->add_option("--model-out", o->model_out,
                  "Write the calibrated model here (HDF5): mu(conditions) as the posterior predictive, its interval the\n"
                  "roughness mean, the coefficients' posterior and delta; served, described and evaluated like any model");
  add_fast_evaluator_options(cmd, o->fast);
  cmd->footer(
      "y_i = mu(x_i, theta) + delta(x_i) + b_set + eps_i: the GP's interval of the mean, the measurement's SD,\n"
      "(with --discrepancy) delta and (for a data set given one) its bias in the likelihood; a condition given\n"
      "with an SD or a range is sampled with the coefficients. Prints each parameter's mean, SD, 95 % credible\n"
      "interval, split-R^ and effective sample size, with how to read them; exit status 2, naming the cause,\n"
      "when the chains fail the limits (split-R^ <= 1.05, ESS >= 400, steps >= 20 autocorrelation times), a\n"
      "measurement lies outside the model's box or cannot be friction (naming its line), the data lack a\n"
      "condition of the model, or the model has no law coefficient. docs/usage.md walks through an example\n"
      "(examples/calibration/).");
  cmd->callback([o] { calibrate_command(*o); });
}

}  // namespace mufric::app
