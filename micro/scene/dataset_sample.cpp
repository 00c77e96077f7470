#include "micro/scene/dataset_sample.hpp"

#include <omp.h>

#include "common/error.hpp"
#include "micro/scene/micro_run.hpp"

namespace mufric::scene {

SampleEvaluator micro_evaluator(const Scene& scene, const InputSpace& inputs, int threads_per_sample) {
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
  return [scene, pressure, velocity, temperature, threads_per_sample](const Eigen::VectorXd& x) {
    omp_set_num_threads(std::max(threads_per_sample, 1));  // this thread's parallel regions
    Scene s = scene;
    s.pressure = x(pressure);
    s.velocity = x(velocity);
    s.temperature = x(temperature);
    const MicroResult r = run_micro(s);
    SampleOutcome o;
    o.converged = r.completed;
    o.mu = r.mu;
    o.failure_reason = r.reason;
    o.diagnostics = {{"contact_area_fraction", r.contact_fraction},
                     {"max_contact_pressure_pa", r.max_contact_pressure},
                     {"max_plastic_strain", r.max_plastic_strain},
                     {"max_temperature_k", r.max_temperature},
                     {"newton_iterations", r.solver.newton_iterations},
                     {"cutbacks", static_cast<double>(r.solver.cutbacks.size())},
                     {"dofs", r.dofs},
                     {"micro_wall_seconds", r.wall_seconds}};
    return o;
  };
}

}  // namespace mufric::scene
