#include "micro/run/dataset_sample.hpp"

#include <algorithm>
#include <limits>

#include <omp.h>

#include "common/error.hpp"
#include "micro/run/measurement.hpp"

namespace mufric::run {
using namespace scene;

SampleEvaluator micro_evaluator(const Scene& scene, const InputSpace& inputs, int threads_per_sample,
                                double sample_wall_seconds) {
  if (!scene.pressure_controlled) {
    throw Error(scene.source + ": load.vertical_displacement: a dataset varies the contact pressure, so the scene must "
                               "give load.pressure");
  }
  // Each input sets the scene key the scene gives it (scene::settable_inputs).
  std::vector<const SettableInput*> known;
  std::string settable;
  for (const SettableInput& k : settable_inputs()) settable += (settable.empty() ? "" : ", ") + std::string(k.input);
  for (const InputSpec& input : inputs) {
    const SettableInput* k = find_settable_input(input.name);
    if (k == nullptr) {
      throw Error("input '" + input.name + "' has no counterpart in a micro-model scene (the inputs a scene sets: " +
                  settable + ")");
    }
    known.push_back(k);
  }
  for (const std::string_view required : {input_name::contact_pressure, input_name::sliding_velocity, input_name::temperature}) {
    if (std::none_of(known.begin(), known.end(), [&](const SettableInput* k) { return k->input == required; })) {
      throw Error("a micro-model dataset needs the inputs contact_pressure, sliding_velocity and temperature");
    }
  }
  // The scene is read again at every plan point, so every check of the scene applies to its values:
  // the box's two corners are read now, before a plan is written. A key the scene's law leaves
  // unread (a shear factor under Coulomb's law) would make a campaign of identical runs: refused.
  for (const bool upper : {false, true}) {
    std::vector<SceneValue> corner;
    for (size_t j = 0; j < known.size(); ++j) corner.push_back({known[j]->scene_key, upper ? inputs[j].hi : inputs[j].lo, known[j]->kind});
    const Scene read = scene_with_values(scene, corner);
    for (const SettableInput* k : known) {
      const auto unread = read.ineffective_keys.find(k->scene_key);
      if (unread != read.ineffective_keys.end()) {
        throw Error("input '" + std::string(k->input) + "' sets " + k->scene_key + ", which has no effect: " +
                    unread->second + " (choose a law that reads it with --set contact.law=...)");
      }
    }
  }
  return [scene, known, threads_per_sample, sample_wall_seconds](const SampleRequest& request) {
    omp_set_num_threads(std::max(threads_per_sample, 1));  // this thread's parallel regions
    std::vector<SceneValue> values;
    for (size_t j = 0; j < known.size(); ++j) values.push_back({known[j]->scene_key, request.x(static_cast<Eigen::Index>(j)), known[j]->kind});
    Scene s = scene_with_values(scene, values);
    if (request.seeds) {  // the row's own surfaces (a measured or flat surface has no seed and stays)
      s.tool_surface.synthetic.seed = request.seeds->tool;
      s.chip_surface.synthetic.seed = request.seeds->chip;
    }
    // The sample's draws (tool phases, realisations) share its cores.
    MeasureOptions options;
    options.threads = std::max(threads_per_sample, 1);
    options.wall_seconds_limit = sample_wall_seconds;
    const MuMeasurement m = measure_mu(s, options);
    SampleOutcome o;
    o.converged = m.completed;
    o.mu = m.mu;
    o.mu_std = m.std_error.value_or(std::numeric_limits<double>::quiet_NaN());
    o.failure_reason = m.reason;
    o.warnings = m.warnings;
    o.diagnostics = m.totals().named_values();
    o.diagnostics["draws"] = static_cast<double>(m.draws.size());
    o.diagnostics["max_abs_drift"] = m.max_abs_drift();
    o.diagnostics["micro_wall_seconds"] = m.wall_seconds;
    for (const auto& d : m.draws) o.draw_mu.push_back(d.result.completed ? d.result.mu : std::numeric_limits<double>::quiet_NaN());
    return o;
  };
}

}  // namespace mufric::run
