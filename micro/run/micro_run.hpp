#pragma once
// One high-fidelity run, dry or lubricated (seed 000 sections 3.1 and 4): the chip interval,
// pressed with p on Γ_B against the rigid rough tool and dragged at v, at initial temperature T; μ
// by eq. (17) from the contact tractions at every step, averaged over a window (scene.protocol:
// seed 000's time window while the load ramps, or press-slide's sliding-distance window after
// pressing). The measurement of μ over several draws is measurement.hpp.
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "micro/run/step_recorder.hpp"
#include "micro/scene/scene.hpp"

namespace mufric::run {

using scene::Scene;

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

MicroResult run_micro(const Scene& scene, const RunOptions& options = {});

// A stopped run's reason with what the scene can change about it: a sealed incompressible film
// whose interface iteration fails has most likely met an enclosed pocket (bench/studies/friction_laws/README.md, "Seed
// 000's sealed film with a compressible liquid"), which a compressible liquid lets the chip follow.
std::string explain_stop(const Scene& scene, const std::string& reason);

// The head every result file starts with (provenance for a file of its own, the outcome, μ) and μ's
// work split: one spelling for a run's and a measurement's result.json.
nlohmann::json result_head(const Scene& scene, bool provenance, bool completed, const std::string& reason,
                           const std::vector<std::string>& warnings, double mu);
nlohmann::json work_split_json(std::optional<double> interface, std::optional<double> plastic,
                               std::optional<double> normal);

}  // namespace mufric::run
