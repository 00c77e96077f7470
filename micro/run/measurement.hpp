#pragma once
// μ as a property of (p, v, T, roughness statistics): a scene's protocol repeated over tool phases
// and realisations (its draws), run in parallel, and the mean with its standard error; its result.json.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "micro/run/micro_run.hpp"

namespace mufric::run {

// One draw of a press-slide measurement: the tool shifted by `shift_fraction` of the interval (on top
// of the scene's own shift) and, for a synthetic tool, drawn with `seed`; the chip surface drawn with
// `chip_seed` when the protocol draws it too (else the scene's own chip).
struct Draw {
  int phase = 0, realisation = 0;
  double shift_fraction = 0.0;
  std::uint64_t seed = 0;
  std::optional<std::uint64_t> chip_seed;
  MicroResult result;
};

// A measurement's work and state over all its draws: sums of work, extremes of state.
struct MeasurementTotals {
  int newton_iterations = 0, cutbacks = 0;
  int coupling_iterations = 0;     // lubricated: fluid–structure exchanges (0 dry)
  double max_contact_pressure = 0.0, max_plastic_strain = 0.0, max_temperature = 0.0;  // Pa, —, K
  double contact_fraction = 0.0;   // mean over the draws, at their ends
  double draw_seconds_sum = 0.0;   // one-core time of all draws together
  int dofs = 0;                    // of the chip (every draw has the same mesh)
  // The diagnostics both result.json and a dataset sample report, under the same keys (one table,
  // kTotalsCounts and kTotalsValues in micro_run.cpp): counts as JSON integers, values as numbers.
  nlohmann::json to_json() const;
  std::map<std::string, double> named_values() const;  // the same, for a dataset's /samples/diagnostics
};

// A draw whose μ moves by more than this fraction of μ between the first and the last block of its
// averaging window is reported: its window may not have reached a steady slide (issue 30 saw 44.8 %;
// the default dry scene at the box centre drifts by 27-36 % within its 2.5 um window, a sign of the
// roughness passing under a 10 um cell, so the warning starts above that).
inline constexpr double kDriftWarningFraction = 0.4;
// A standard error from fewer draws than this is reported as itself uncertain (±71 % from 2 draws, ±50 % from 3).
inline constexpr size_t kFewDrawsForStdError = 4;

// μ as a property of (p, v, T, roughness statistics): the mean over the draws, with the standard
// error of that mean (sample standard deviation / √draws; none for a single draw).
struct MuMeasurement {
  bool completed = false;
  std::string reason;
  double mu = 0.0;
  std::optional<double> std_error;
  std::vector<Draw> draws;
  // The draws' warnings, each once (a molten chip): a dataset keeps such a sample outside the model.
  std::vector<std::string> warnings;
  // Warnings that leave μ in the model (a drifting window, few draws, keys without effect): printed
  // and in result.json's "warnings" beside the above, but a dataset trains on the sample.
  std::vector<std::string> advisories;
  double wall_seconds = 0.0;
  int threads = 1;  // draws run at once
  double max_abs_drift() const;
  MeasurementTotals totals() const;
  nlohmann::json to_json(const Scene& scene) const;
};

struct MeasureOptions {
  int threads = 0;            // cores to use (draws run in parallel); 0: usable_cores()
  double wall_seconds_limit = 0.0;  // > 0: the whole measurement stops with an Error after this long
  std::string vtu_directory;  // VTU of the first draw
  // progress: the draw (index into draws) and its step; called from the draws' threads, serialised
  std::function<void(int, const MicroStep&, const Scene&)> on_step;
};

// The draws a scene's protocol asks for (one for seed 000's).
std::vector<Draw> protocol_draws(const Scene& scene);
// The scene of one draw.
Scene draw_scene(const Scene& scene, const Draw& draw);
MuMeasurement measure_mu(const Scene& scene, const MeasureOptions& options = {});
// Advisories of a completed measurement: a draw whose window drifted by more than kDriftWarningFraction,
// a standard error from fewer than kFewDrawsForStdError draws.
void add_measurement_advisories(MuMeasurement& m);

}  // namespace mufric::run
