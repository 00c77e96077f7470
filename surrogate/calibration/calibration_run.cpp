#include "surrogate/calibration/calibration_run.hpp"

#include <algorithm>
#include <chrono>

#include "common/error.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"
#include "surrogate/calibration/coefficient_evidence.hpp"
#include "surrogate/calibration/held_out_check.hpp"

namespace mufric {
namespace {

void tell(const CalibrationSay& say, const std::string& text) {
  if (say) say(text);
}

std::string describe_setup(const CalibrationSetup& setup) {
  const CalibrationProblem& problem = *setup.problem;
  std::string text;
  for (const std::string& warning : setup.warnings) text += "warning: " + warning + "\n";
  text += "calibrating " + count_of(problem.parameter_count(), "coefficient", "coefficients") + " against " +
          count_of(problem.data().rows(), "measurement", "measurements") + " in " +
          count_of(static_cast<long long>(problem.data().data_sets.size()), "data set", "data sets") + ", discrepancy " +
          (problem.discrepancy() ? "on" : "off");
  if (problem.priors().discrepancy_trend_sd > 0.0) {
    text += text_printf(" with a linear trend (its coefficients normal(0, %g))", problem.priors().discrepancy_trend_sd);
  }
  if (problem.latent_count() > 0) {
    text += text_printf(", %lld conditions with their uncertainty", static_cast<long long>(problem.latent_count()));
  }
  text += "\n";
  for (Eigen::Index k = 0; k < problem.parameter_count(); ++k) {
    const std::string& name = problem.parameters()[static_cast<size_t>(k)];
    text += "  prior of " + name + ": " + problem.prior_of(k).describe(kind_of_input(name)) + "\n";
  }
  for (const auto& [name, value] : problem.held()) {
    text += "  held: " + name + " = " + format_human(value, kind_of_input(name)) + "\n";
  }
  for (const auto& [set, prior] : problem.priors().biases) text += "  bias of data set " + set + ": " + prior.describe() + "\n";
  return text;
}

std::string describe_posterior(const CalibrationProblem& problem, const CalibrationResult& result, double seconds) {
  std::string text = text_printf("%-40s %12s %12s %27s %9s %7s\n", "parameter", "mean", "sd", "95 % credible interval",
                                 "split-R^", "ESS");
  for (size_t j = 0; j < result.summary.size(); ++j) {
    const ParameterSummary& s = result.summary[j];
    const QuantityKind kind = problem.coordinate_kind(static_cast<Eigen::Index>(j));
    const std::string interval = format_human(s.lo95, kind) + " .. " + format_human(s.hi95, kind);
    text += text_printf("%-40s %12s %12s %27s %9.4f %7.0f\n", s.name.c_str(), format_human(s.mean, kind).c_str(),
                        format_human_difference(s.sd, kind).c_str(), interval.c_str(), s.split_rhat, s.effective_sample_size);
  }
  text += text_printf("%d walkers x %d steps after %d burn-in, seed %llu; acceptance %.2f; %.1f s\n", result.options.walkers,
                      result.options.steps, result.options.burn_in_steps,
                      static_cast<unsigned long long>(result.options.seed), result.acceptance, seconds);
  text += text_printf(
      "how to read it: split-R^ compares each walker's two halves and the walkers with each other (1 when they agree; "
      "used only at <= %.2f); ESS is the number of independent samples the chains are worth (used only at >= %.0f); "
      "acceptance is the share of proposed moves taken (0.2-0.5 is usual for this sampler; near 0, the walkers are stuck)\n",
      kMaximumSplitRhat, kMinimumEffectiveSamples);
  if (problem.discrepancy()) text += "discrepancy_amplitude in mu units, discrepancy_length_scale in widths of the model's box\n";
  if (problem.bias_count() > 0) text += "bias[set]: what that data set measures above the others, mu units\n";
  if (problem.latent_count() > 0) {
    text += "the rows' conditions given with an uncertainty: what the data imply of them (their prior: the stated SD or range)\n";
  }
  const auto evidence = coefficient_evidence(problem, result);
  text += describe_evidence(problem, evidence);
  for (const std::string& warning : evidence_warnings(problem, evidence)) text += "warning: " + warning + "\n";
  text += describe_held_out(problem, leave_one_out(problem, result));
  return text;
}

// The sampler's (done, total) as a line every tenth of the steps, and one when a run goes on.
SamplerProgress tenths_of_the_steps(const CalibrationSay& progress) {
  if (!progress) return {};
  return [progress, reported = 0, run = 0](int done, int total) mutable {
    if (done == 1) {
      reported = 0;
      if (run++ > 0) progress(text_printf("not yet within the limits: running on for %d steps", total));
    }
    const int tenth = done * 10 / total;
    if (tenth > reported) {
      reported = tenth;
      progress(text_printf("%d %% of the steps (%d of %d)", tenth * 10, done, total));
    }
  };
}

}  // namespace

EnsembleOptions calibration_sampler(const CalibrationProblem& problem, const CalibrationRunOptions& options) {
  EnsembleOptions sampler = options.sampler;
  const int dimension = static_cast<int>(problem.dimension());
  if (options.automatic_walkers) sampler.walkers = std::max(sampler.walkers, 4 * dimension);
  if (sampler.walkers < 2 * dimension + 2) {
    throw Error("--walkers " + std::to_string(sampler.walkers) + ": the posterior has " + std::to_string(dimension) +
                " coordinates; give at least " + std::to_string(2 * dimension + 2) + " walkers");
  }
  return sampler;
}

CalibrationRun sample_calibration(CalibrationSetup setup, const CalibrationRunOptions& options) {
  const CalibrationProblem& problem = *setup.problem;
  tell(options.report, describe_setup(setup));
  const EnsembleOptions sampler = calibration_sampler(problem, options);
  const auto started = std::chrono::steady_clock::now();
  CalibrationResult result = calibrate(problem, sampler, tenths_of_the_steps(options.progress));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  tell(options.report, describe_posterior(problem, result, seconds));
  return CalibrationRun{std::move(setup), std::move(result), seconds};
}

CalibrationRun run_calibration(std::shared_ptr<const GaussianProcess> emulator, const CalibrationRequest& request,
                               const CalibrationRunOptions& options) {
  CalibrationRun run = sample_calibration(prepare_calibration(std::move(emulator), request), options);
  if (!run.result.convergence_failure.empty()) {
    throw Error("the posterior is not usable, nothing written: " + run.result.convergence_failure);
  }
  return run;
}

CalibrationRun recalibrate(const CalibratedModel& model, std::shared_ptr<const GaussianProcess> emulator, int max_steps,
                           const CalibrationSay& report, const CalibrationSay& progress) {
  CalibrationRunOptions options{.automatic_walkers = false, .report = report, .progress = progress};
  options.sampler.walkers = model.record().walkers;
  options.sampler.steps = model.record().steps;
  options.sampler.burn_in_steps = model.record().burn_in_steps;
  options.sampler.seed = model.record().seed;
  options.sampler.max_steps = max_steps;
  return sample_calibration(recalibration_setup(model, std::move(emulator)), options);
}

PosteriorSamplesCsv posterior_samples_csv(const CalibrationRun& run, long long most_rows, const std::string& provenance) {
  const Eigen::MatrixXd& samples = run.result.samples;
  const long long kept = samples.rows();
  const long long stride = most_rows > 0 ? std::max(1LL, (kept + most_rows - 1) / most_rows) : 1;
  std::string text = "# posterior samples of mufric calibrate (natural units: SI for inputs and conditions): ";
  text += stride == 1 ? "every walker's kept states, " + std::to_string(kept)
                      : "every " + std::to_string(stride) + "th of the walkers' " + std::to_string(kept) +
                            " kept states (--out-samples 0 for all)";
  text += "\n# " + provenance + "\n";
  const auto& names = run.setup.problem->coordinate_names();
  for (size_t j = 0; j < names.size(); ++j) {
    if (j > 0) text += ',';
    text += names[j];
  }
  text += "\n";
  for (long long i = 0; i < kept; i += stride) {
    for (Eigen::Index j = 0; j < samples.cols(); ++j) {
      if (j > 0) text += ',';
      text += text_printf("%.17g", samples(i, j));
    }
    text += "\n";
  }
  return PosteriorSamplesCsv{std::move(text), (kept + stride - 1) / stride, kept};
}

std::string describe_calibrated_centre(const CalibratedModel& model) {
  const IntervalParts& c = model.centre_parts();
  return text_printf("at the box centre: mu %.4g, sd %.3g = sqrt(law coefficients %.3g^2 + given them %.3g^2); "
                     "alone: roughness mean %.3g, discrepancy %.3g (parts alone need not add up: given the data, what one "
                     "explains the other need not)\n",
                     c.mu, c.sd, c.parameter_sd, c.conditional_sd, c.emulator_sd, c.discrepancy_sd);
}

}  // namespace mufric
