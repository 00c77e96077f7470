// `mufric calibrate`: the posterior of an interface law's coefficients given measured friction,
// through the GP of a campaign that varied them (surrogate/calibration/calibration.hpp).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/fast_evaluator_options.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/calibration/calibration_run.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric::app {
namespace {

constexpr long long kDefaultPosteriorRows = 4000;

struct CalibrateOptions {
  std::string model, out, model_out;
  CalibrationRequest request;
  FastOptions fast;  // the calibrated model's grid
  CalibrationRunOptions run{
      .report = [](const std::string& text) {
        std::fputs(text.c_str(), stdout);
        std::fflush(stdout);
      },
      .progress = [](const std::string& line) { std::fprintf(stderr, "calibrate: %s\n", line.c_str()); }};
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

void calibrate_command(const CalibrateOptions& o) {
  const CalibrationRun run = run_calibration(load_emulator(o.model), o.request, o.run);
  if (!o.out.empty()) {
    std::string provenance = "model " + o.model + ", measurements";
    for (const std::string& data : o.request.data_files) provenance += " " + data;
    provenance += (o.request.priors_file.empty() ? "" : ", priors " + o.request.priors_file) + ", seed " +
                  std::to_string(o.run.sampler.seed);
    const PosteriorSamplesCsv csv = posterior_samples_csv(run, o.out_samples, provenance);
    write_file_atomically(o.out, csv.text);
    std::printf("wrote %s (%lld of %lld kept samples%s)\n", o.out.c_str(), csv.rows, csv.kept,
                csv.rows < csv.kept ? ", evenly thinned; --out-samples 0 for all" : "");
  }
  if (o.model_out.empty()) return;
  // The calibrated model: served like any other, with a fast evaluator certified against it.
  CalibratedModel model = calibrated_model(run.setup, run.result);
  attach_fast_evaluator(model, o.fast);
  if (o.fast.skip) std::printf("no fast evaluator (--no-fast-evaluator): the exact posterior predictive answers\n");
  save_model(o.model_out, model);
  std::printf("wrote %s (calibrated model of", o.model_out.c_str());
  for (const InputSpec& input : model.inputs()) std::printf(" %s", input.name.c_str());
  std::printf(")\n%s", describe_calibrated_centre(model).c_str());
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
  cmd->add_option("--walkers", o->run.sampler.walkers,
                  "Ensemble walkers (Goodman & Weare 2010); default: 32, or four per posterior coordinate when more")
      ->check(CLI::Range(4, 100000))
      ->each([o](const std::string&) { o->run.automatic_walkers = false; });
  cmd->add_option("--burn-in", o->run.sampler.burn_in_steps, "Steps discarded")->capture_default_str()->check(CLI::Range(0, 10000000));
  cmd->add_option("--steps", o->run.sampler.steps, "Steps kept")->capture_default_str()->check(CLI::Range(4, 10000000));
  cmd->add_option("--max-steps", o->run.sampler.max_steps,
                  "A run not yet within the limits goes on, its length doubling, up to this many steps in all, and is\n"
                  "judged on its latest run (0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100000000));
  cmd->add_option("--seed", o->run.sampler.seed, "Seed: the same seed, data and model give the same posterior, bit for bit")
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
