#pragma once
// What runs a campaign's samples for `dataset run`, `dataset refine` and `learn`: the micro-model with
// the database's scene, or a model file standing in for it (--simulator: a law or a GP's μ, to try a
// campaign's machinery in seconds; its database's scene then names the simulator, so that its
// samples never mix with the micro-model's).
#include <string>
#include <vector>

#include "common/dataset_file.hpp"
#include "common/sample_outcome.hpp"
#include "micro/scene/scene.hpp"

namespace mufric::app {

// The scene of a run: scene_path (or the one stored with the plan, or the default), then overrides.
scene::Scene run_scene(const std::string& scene_path, const std::vector<std::string>& overrides, const Dataset& plan,
                       const std::string& plan_path);
// Threads per sample: `threads`, or the usable cores shared among the jobs.
int threads_per_job(int jobs, int threads);

// The scene text a simulator's database stores: {"simulator": the file's name, "sha256": its content's}.
std::string simulator_scene_json(const std::string& model_path);
// The model's μ at each sample's point (converged; its σ as the sample's standard error when it has one).
SampleEvaluator simulator_evaluator(const std::string& model_path, const InputSpace& inputs);
// The evaluator of a database's samples: the micro-model with its stored scene, or with `simulator`
// the model file, which the database's scene must name (an Error names the mismatch).
SampleEvaluator database_evaluator(const Dataset& db, const std::string& db_path, const std::string& simulator,
                                   int threads_per_sample, double sample_timeout);

}  // namespace mufric::app
