#include "app/sample_evaluators.hpp"

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <memory>

#include <nlohmann/json.hpp>

#include "common/environment.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "micro/run/dataset_sample.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric::app {

scene::Scene run_scene(const std::string& scene_path, const std::vector<std::string>& overrides, const Dataset& plan,
                       const std::string& plan_path) {
  if (!scene_path.empty() || plan.scene_json.empty()) return scene::load_scene(scene_path, overrides);
  return scene::scene_with_overrides(nlohmann::json::parse(plan.scene_json), overrides, "the scene of " + plan_path);
}

int threads_per_job(int jobs, int threads) { return threads > 0 ? threads : std::max(1, usable_cores() / jobs); }

std::string simulator_scene_json(const std::string& model_path) {
  // The file's name and content, not its path: the same simulator from another directory (a Slurm
  // task's) is the same scene.
  return nlohmann::json{{"simulator", std::filesystem::path(model_path).filename().string()}, {"sha256", sha256_file(model_path)}}.dump(2);
}

SampleEvaluator simulator_evaluator(const std::string& model_path, const InputSpace& inputs) {
  std::shared_ptr<const FrictionModel> model = load_model_isolated(model_path);
  return [model, inputs, model_path](const SampleRequest& r) {
    const QueryBatch x = align_inputs(r.x.transpose(), inputs, model->inputs(), model_path);
    EvaluationRequest what;
    what.std = model->has_uncertainty();
    what.max_threads = 1;
    what.extrapolation = Extrapolation::raw;  // the simulator's own formula wherever the campaign's box goes
    const Evaluation e = model->evaluate(x, what);
    SampleOutcome o;
    if (!std::isfinite(e.mu(0))) {
      o.failure_reason = "the simulator " + model_path + " gives no mu here";
      return o;
    }
    o.converged = true;
    o.mu = e.mu(0);
    if (what.std) o.mu_std = e.std(0);
    return o;
  };
}

SampleEvaluator database_evaluator(const Dataset& db, const std::string& db_path, const std::string& simulator,
                                   int threads_per_sample, double sample_timeout) {
  const bool simulated = db.scene_json.find("\"simulator\"") != std::string::npos;
  if (!simulator.empty()) {
    if (!simulated) throw Error(db_path + ": its samples are the micro-model's; --simulator runs only a simulator's database");
    const std::string made_by = nlohmann::json::parse(db.scene_json).value("sha256", std::string());
    if (made_by != sha256_file(simulator)) {
      throw Error(db_path + ": its samples were made by another simulator (" + db.scene_json + ") than " + simulator);
    }
    return simulator_evaluator(simulator, db.inputs);
  }
  if (simulated) throw Error(db_path + ": its samples come from a simulator (its scene: " + db.scene_json + "); give it with --simulator");
  const scene::Scene sc = run_scene("", {}, db, db_path);
  return run::micro_evaluator(sc, db.inputs, threads_per_sample, sample_timeout);
}

}  // namespace mufric::app
