#pragma once
// A calibration run from set-up to a usable posterior, one policy for `mufric calibrate` and the
// learner's recalibration: how many walkers, how far the chains run on, what is said while they run
// and after (the set-up, the summary table, what the data hardly inform), and the posterior's CSV.
// Front ends parse options and choose where the words go; the run's decisions are made here.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "surrogate/calibration/calibration_workflow.hpp"

namespace mufric {

// One line (or paragraph, ending in '\n') for the user; a front end prints it or logs it.
using CalibrationSay = std::function<void(const std::string& text)>;

struct CalibrationRunOptions {
  EnsembleOptions sampler = [] {
    EnsembleOptions o;
    o.max_steps = kDefaultCalibrationMaxSteps;
    return o;
  }();
  // Walkers not chosen by the user: at least four per coordinate (the stretch move needs more than
  // two, and mixes better with more). A user's count is taken as given, and checked.
  bool automatic_walkers = true;
  CalibrationSay report;    // the set-up, the summary and its warnings (calibrate: stdout)
  CalibrationSay progress;  // every tenth of the steps, and a run going on (calibrate: stderr)
};

struct CalibrationRun {
  CalibrationSetup setup;
  CalibrationResult result;  // convergence_failure says when its chains are not usable
  double seconds = 0.0;      // the sampling's wall time
};

// The sampler a problem is run with: options.sampler with the walker policy above. Throws Error
// naming --walkers when the count is too few for the posterior's coordinates.
EnsembleOptions calibration_sampler(const CalibrationProblem& problem, const CalibrationRunOptions& options);

// Samples a set-up calibration and says what it found (report: the set-up before, the summary and
// the posterior's warnings after). Does not throw on unusable chains: the caller decides.
CalibrationRun sample_calibration(CalibrationSetup setup, const CalibrationRunOptions& options);

// The whole run of `mufric calibrate`: read and check the request, sample, diagnose. Throws Error
// naming the cause, unusable chains included ("nothing written").
CalibrationRun run_calibration(std::shared_ptr<const GaussianProcess> emulator, const CalibrationRequest& request,
                               const CalibrationRunOptions& options);

// A calibrated model's calibration run again with another emulator: its campaign's GP retrained on
// more runs (`mufric learn`). Set up by recalibration_setup (which throws for what cannot be run
// again), sampled with the sampler its record keeps (walkers, steps, burn-in, seed); a run not within
// the limits goes on up to max_steps. The result's convergence_failure says when its chains are not usable.
CalibrationRun recalibrate(const CalibratedModel& model, std::shared_ptr<const GaussianProcess> emulator,
                           int max_steps = kDefaultCalibrationMaxSteps, const CalibrationSay& report = {},
                           const CalibrationSay& progress = {});

// What `--out` holds: the kept samples evenly thinned to at most `most_rows` (0: all), one column per
// coordinate, natural units, after two '#' lines saying what was thinned and where it came from
// (`provenance`, e.g. the model, the data and the seed).
struct PosteriorSamplesCsv {
  std::string text;
  long long rows = 0, kept = 0;
};
PosteriorSamplesCsv posterior_samples_csv(const CalibrationRun& run, long long most_rows, const std::string& provenance);

// A calibrated model's centre in words: the prediction and its interval's parts at the box centre.
std::string describe_calibrated_centre(const CalibratedModel& model);

}  // namespace mufric
