#pragma once
// One high-fidelity run, dry or lubricated (seed 000 sections 3.1 and 4): the chip interval,
// pressed with p on Γ_B against the rigid rough tool and dragged at v, at initial temperature T; μ
// by eq. (17) from the contact tractions at every step, averaged over a window (scene.protocol:
// seed 000's time window while the load ramps, or press-slide's sliding-distance window after
// pressing). measure_mu repeats the run over tool phases and realisations and reports the mean with
// its standard error.
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "micro/contact/mortar_contact.hpp"
#include "micro/coupling/lubricated_chip.hpp"
#include "micro/scene/scene.hpp"

namespace mufric::scene {

struct MicroStep {
  double time = 0.0;
  double sliding_distance = 0.0;                    // m, of Γ_B since sliding started
  std::optional<double> mu;                         // ∫Tx/∫Ty; none while nothing touches
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  // resultant on the chip (contact + lubricant), N/m
  // Lubricated, once the film has formed: the lubricant's own record of the step (its force on the
  // chip, coupling work, film, pockets, cavities, liquid), as the coupled step wrote it.
  std::optional<coupling::LubricatedStep> lubricant;
  double contact_fraction = 0.0;                    // of the interval's surface length
  // Of the length in contact, the part whose spots the lubricant wets (they take the wetted law; 0 dry).
  double wetted_contact_fraction = 0.0;
  double max_pressure = 0.0;                        // Pa
  int newton_iterations = 0;
  // Since the start, J per unit depth: the energy the interfacial law dissipated at the contact, and
  // the chip's plastic work Σ w σ_y Δε̄ᵖ (0 for the frictionless law / an elastic chip).
  double interface_dissipation = 0.0, plastic_work = 0.0;
  double bottom_rise = 0.0;  // m: Γ_B's mean vertical displacement (toward the tool positive)
};

// A lubricated run's film record: coupling work, mesh quality, the lubricant's area and its pockets.
// (At namespace scope: clang cannot default-construct a nested struct with member initialisers
// inside std::optional while the enclosing class is incomplete.)
struct LubricantRecord {
  int coupling_iterations = 0, max_coupling_iterations = 0, fluid_newton_iterations = 0;
  int coupling_restarts = 0;  // in the accepted steps
  double min_relative_jacobian = 1.0;
  double initial_film_area = 0.0, final_film_area = 0.0;  // m² per unit depth, when formed and at the end
  double initial_liquid_area = 0.0, final_liquid_area = 0.0;  // the same of the liquid (film less cavities)
  std::vector<double> final_pocket_areas;                  // m² per unit depth
  double leaked_area = 0.0;     // m² per unit depth, summed over the steps: the liquid that left the plane, net
  double exchanged_area = 0.0;  // the same of the liquid that moved out of the plane in one direction
  int fluid_dofs = 0;
};

struct MicroResult {
  bool completed = false;
  std::string reason;           // why not, if not
  double mu = 0.0;              // average over the protocol's window
  int averaged_steps = 0;
  // press-slide: μ averaged over equal-distance blocks of the window, and the relative drift
  // (last block − first block) / μ; empty/0 for seed 000's protocol.
  std::vector<double> block_means;
  double drift = 0.0;
  // μ's work split over the same window: the interface's frictional dissipation and the chip's
  // plastic work per unit sliding distance and normal force (the adhesive and the ploughing share).
  // Their sum differs from μ by the elastic energy stored and the kinetic energy over the window.
  std::optional<double> mu_interface_work, mu_plastic_work;
  // The normal load's work over the window per unit sliding distance and normal force: Γ_B's rise
  // per unit slide (a tool settling into the chip, or riding up, converts work between the two
  // directions: μ + this = the two parts above + the stored energy).
  std::optional<double> mu_normal_work;
  double slide_start_time = 0.0;  // s, when Γ_B starts to move (0 for seed 000)
  std::vector<MicroStep> history;
  double contact_fraction = 0.0, max_contact_pressure = 0.0;  // at the end
  double max_plastic_strain = 0.0, max_temperature = 0.0;     // over the chip, at the end
  contact::ContactState final_contact;  // at the end: per surface point pressure (for verification)
  // A completed run whose result lies outside what the model describes (the chip reached its
  // melting temperature, where Johnson–Cook leaves it no strength), one sentence each.
  std::vector<std::string> warnings;
  int dofs = 0, elements = 0;
  std::optional<LubricantRecord> lubricant;  // lubricated runs
  solid::IntegrationReport solver;  // the time integration's own record: Newton work, cut-backs, seconds
  double wall_seconds = 0.0;
  // provenance: code version, time and scene (false for a draw inside a measurement's file)
  nlohmann::json to_json(const Scene& scene, bool provenance = true) const;
};

struct RunOptions {
  std::string vtu_directory;  // empty: no VTU output; else chip.vtu and tool.vtu at the end
  std::function<void(const MicroStep&, const Scene&)> on_step;  // progress
  // A run still stepping at this time stops with an Error naming the limit and where it stopped
  // (a dataset's sample that would hold up its shard; checked after every accepted step).
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  double wall_seconds_limit = 0.0;  // what the deadline came from, for the message
};

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

// The chip surface and the tool surface as fitted periodic curves, the tool placed above the chip
// at the scene's initial gap.
struct SceneGeometry {
  spline::SplineCurve chip_surface, tool_surface;
};
SceneGeometry build_geometry(const Scene& scene);

MicroResult run_micro(const Scene& scene, const RunOptions& options = {});

// A stopped run's reason with what the scene can change about it: a sealed incompressible film
// whose interface iteration fails has most likely met an enclosed pocket (bench/RESULTS.md, "Seed
// 000's sealed film with a compressible liquid"), which a compressible liquid lets the chip follow.
std::string explain_stop(const Scene& scene, const std::string& reason);

}  // namespace mufric::scene
