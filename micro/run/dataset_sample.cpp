#include "micro/run/dataset_sample.hpp"

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
  int pressure = -1, velocity = -1, temperature = -1;
  for (size_t j = 0; j < inputs.size(); ++j) {
    const std::string& name = inputs[j].name;
    if (name == "contact_pressure") {
      pressure = static_cast<int>(j);
    } else if (name == "sliding_velocity") {
      velocity = static_cast<int>(j);
    } else if (name == "temperature") {
      temperature = static_cast<int>(j);
    } else {
      throw Error("input '" + name + "' has no counterpart in a micro-model scene (it sets contact_pressure, "
                  "sliding_velocity and temperature)");
    }
  }
  if (pressure < 0 || velocity < 0 || temperature < 0) {
    throw Error("a micro-model dataset needs the inputs contact_pressure, sliding_velocity and temperature");
  }
  return [scene, pressure, velocity, temperature, threads_per_sample, sample_wall_seconds](const SampleRequest& request) {
    omp_set_num_threads(std::max(threads_per_sample, 1));  // this thread's parallel regions
    const Eigen::VectorXd& x = request.x;
    Scene s = scene;
    if (request.seeds) {  // the row's own surfaces (a measured or flat surface has no seed and stays)
      s.tool_surface.synthetic.seed = request.seeds->tool;
      s.chip_surface.synthetic.seed = request.seeds->chip;
    }
    s.pressure = x(pressure);
    s.velocity = x(velocity);
    s.temperature = x(temperature);
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
