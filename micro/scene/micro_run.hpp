#pragma once
// One high-fidelity dry run (seed 000 sections 3.1 and 4): the chip interval, pressed with p on Γ_B
// against the rigid rough tool and dragged at v, at initial temperature T; μ by eq. (17) from the
// contact tractions at every step and time-averaged over a window.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "micro/contact/mortar_contact.hpp"
#include "micro/scene/scene.hpp"

namespace mufric::scene {

struct MicroStep {
  double time = 0.0;
  std::optional<double> mu;                         // ∫Tx/∫Ty; none while nothing touches
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  // contact resultant on the chip, N/m
  double contact_fraction = 0.0;                    // of the interval's surface length
  double max_pressure = 0.0;                        // Pa
  int newton_iterations = 0;
};

struct MicroResult {
  bool completed = false;
  std::string reason;           // why not, if not
  double mu = 0.0;              // time average over [average_from, duration]
  int averaged_steps = 0;
  std::vector<MicroStep> history;
  double contact_fraction = 0.0, max_contact_pressure = 0.0;  // at the end
  double max_plastic_strain = 0.0, max_temperature = 0.0;     // over the chip, at the end
  // A completed run whose result lies outside what the model describes (the chip reached its
  // melting temperature, where Johnson–Cook leaves it no strength), one sentence each.
  std::vector<std::string> warnings;
  int dofs = 0, elements = 0;
  solid::IntegrationReport solver;  // the time integration's own record: Newton work, cut-backs, seconds
  double wall_seconds = 0.0;
  nlohmann::json to_json(const Scene& scene) const;
};

struct RunOptions {
  std::string vtu_directory;  // empty: no VTU output; else chip.vtu and tool.vtu at the end
  std::function<void(const MicroStep&, const Scene&)> on_step;  // progress
};

// The chip surface and the tool surface as fitted periodic curves, the tool placed above the chip
// at the scene's initial gap.
struct SceneGeometry {
  spline::SplineCurve chip_surface, tool_surface;
};
SceneGeometry build_geometry(const Scene& scene);

MicroResult run_micro(const Scene& scene, const RunOptions& options = {});

}  // namespace mufric::scene
