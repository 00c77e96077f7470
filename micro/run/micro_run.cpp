#include "micro/run/micro_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "common/units.hpp"
#include "common/version.hpp"
#include "micro/coupling/partitioned.hpp"
#include "micro/run/chip_model.hpp"
#include "micro/run/vtu.hpp"

namespace mufric::run {
using namespace scene;

nlohmann::json result_head(const Scene& scene, bool provenance, bool completed, const std::string& reason,
                           const std::vector<std::string>& warnings, double mu) {
  nlohmann::json j;
  if (provenance) {
    j["code_version"] = code_version();
    j["created_utc"] = utc_timestamp();
    j["scene"] = scene.effective;
  }
  j["completed"] = completed;
  if (!completed) j["reason"] = reason;
  j["warnings"] = warnings;
  j["mu"] = completed ? nlohmann::json(mu) : nlohmann::json(nullptr);
  return j;
}

nlohmann::json work_split_json(std::optional<double> interface, std::optional<double> plastic,
                               std::optional<double> normal) {
  const auto value = [](std::optional<double> v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  return {{"mu_interface", value(interface)},
          {"mu_bulk_plastic", value(plastic)},
          {"mu_normal_load", value(normal)},
          {"means", "over mu's window, each per unit sliding distance and normal force: the interfacial law's "
                    "frictional dissipation (mu's adhesive part), the chip's plastic work (its ploughing part), and "
                    "the normal load's work as the chip's bottom rises toward the tool; mu + mu_normal_load = "
                    "mu_interface + mu_bulk_plastic + the energy the window stores"}};
}

nlohmann::json MicroResult::to_json(const Scene& scene, bool provenance) const {
  nlohmann::json j = result_head(scene, provenance, completed, reason, warnings, mu);
  if (scene.protocol.name == Protocol::seed000) {
    j["mu_window_s"] = {scene.average_from, scene.duration};
  } else {
    j["mu_window_sliding_distance_m"] = {scene.protocol.run_in, scene.protocol.run_in + scene.protocol.window};
    j["slide_start_s"] = slide_start_time;
  }
  j["averaged_steps"] = averaged_steps;
  if (mu_interface_work || mu_plastic_work) j["work_split"] = work_split_json(mu_interface_work, mu_plastic_work, mu_normal_work);
  j["diagnostics"] = {{"contact_area_fraction", contact_fraction},
                      {"max_contact_pressure_pa", max_contact_pressure},
                      {"max_plastic_strain", max_plastic_strain},
                      {"max_temperature_k", max_temperature},
                      {"newton_iterations", solver.newton_iterations},
                      {"cutbacks", static_cast<int>(solver.cutbacks.size())},
                      {"dofs", dofs},
                      {"elements", elements},
                      {"wall_seconds", wall_seconds},
                      {"assemblies", solver.assemblies},
                      {"line_search_reductions", solver.line_search_reductions},
                      {"unpredicted_convergence", solver.unpredicted_convergence},
                      {"lu_fallbacks", solver.lu_fallbacks},
                      {"krylov_iterations", solver.krylov_iterations},
                      {"assembly_seconds", solver.seconds_assembly},
                      {"contact_seconds", solver.seconds_contact},
                      {"solve_seconds", solver.seconds_solve},
                      {"heat_conduction_seconds", solver.seconds_after_step}};
  if (lubricant) {
    j["lubricant"] = {{"coupling_iterations", lubricant->coupling_iterations},
                      {"max_coupling_iterations_per_step", lubricant->max_coupling_iterations},
                      {"coupling_restarts", lubricant->coupling_restarts},
                      {"fluid_newton_iterations", lubricant->fluid_newton_iterations},
                      {"min_relative_jacobian", lubricant->min_relative_jacobian},
                      {"film_area_m2_per_m", {lubricant->initial_film_area, lubricant->final_film_area}},
                      {"liquid_area_m2_per_m", {lubricant->initial_liquid_area, lubricant->final_liquid_area}},
                      {"leaked_area_m2_per_m", lubricant->leaked_area},
                      {"exchanged_area_m2_per_m", lubricant->exchanged_area},
                      {"final_pocket_areas_m2_per_m", lubricant->final_pocket_areas},
                      {"fluid_dofs", lubricant->fluid_dofs}};
  }
  auto& cuts = j["cutbacks"] = nlohmann::json::array();
  for (const auto& c : solver.cutbacks) cuts.push_back({{"time_s", c.time}, {"dt_failed_s", c.dt_failed}, {"reason", c.reason}});
  auto& h = j["history"] = nlohmann::json::array();
  for (const auto& s : history) {
    const coupling::LubricatedStep film = s.lubricant.value_or(coupling::LubricatedStep{});  // dry: all zero
    h.push_back({{"time_s", s.time},
                 {"sliding_distance_m", s.sliding_distance},
                 {"mu", s.mu ? nlohmann::json(*s.mu) : nlohmann::json(nullptr)},
                 {"force_x_n_per_m", s.force.x()},
                 {"force_y_n_per_m", s.force.y()},
                 {"fluid_force_x_n_per_m", film.fluid_force.x()},
                 {"fluid_force_y_n_per_m", film.fluid_force.y()},
                 {"coupling_iterations", film.coupling_iterations},
                 {"film_area_m2_per_m", film.film_area},
                 {"pocket_areas_m2_per_m", film.pocket_areas},
                 {"cavitated_fraction", film.cavitated_fraction},
                 {"cavity_area_m2_per_m", film.cavity_area},
                 {"liquid_area_m2_per_m", film.liquid_area},
                 {"leaked_area_m2_per_m", film.leaked_area},
                 {"film_volume_error", film.volume_error},
                 {"contact_area_fraction", s.contact_fraction},
                 {"wetted_contact_fraction", s.wetted_contact_fraction},
                 {"max_contact_pressure_pa", s.max_pressure},
                 {"interface_dissipation_j_per_m", s.interface_dissipation},
                 {"plastic_work_j_per_m", s.plastic_work},
                 {"bottom_rise_m", s.bottom_rise},
                 {"newton_iterations", s.newton_iterations}});
  }
  return j;
}

namespace {

// A run's wall-time limit, checked in two places: after every failed attempt of a step (so that a
// step that keeps failing does not outlast it by its cut-backs) and after every accepted step (where
// the message can say how far the run got).
class WallTimeLimit {
 public:
  explicit WallTimeLimit(const RunOptions& options) : deadline_(options.deadline) {
    std::snprintf(message_, sizeof message_, "wall-time limit of %g s reached", options.wall_seconds_limit);
  }
  void watch_failed_attempts(solid::TimeIntegrationOptions& o) {
    if (deadline_ == std::chrono::steady_clock::time_point::max()) return;
    o.should_stop = [this](std::string& reason) {
      if (!passed()) return false;
      reason = message_;
      stopped_a_failing_step_ = true;
      return true;
    };
  }
  // Throws (a failed sample) when the limit has passed after an accepted step.
  void check_accepted_step(const MicroStep& step, size_t steps) const {
    if (!passed()) return;
    char where[120];
    std::snprintf(where, sizeof where, " at t = %.4g s (sliding distance %.4g um, step %zu)", step.time,
                  1e6 * step.sliding_distance, steps);
    throw Error(message_ + std::string(where));
  }
  // A run that stopped inside a failing step fails like one stopped after an accepted step.
  void check_report(const solid::IntegrationReport& report) const {
    if (stopped_a_failing_step_) throw Error(report.reason);
  }

 private:
  bool passed() const { return std::chrono::steady_clock::now() > deadline_; }
  std::chrono::steady_clock::time_point deadline_;
  char message_[80];
  bool stopped_a_failing_step_ = false;
};

// The lubricant's totals over the accepted steps, and its film when formed and at the end.
LubricantRecord lubricant_record(const coupling::LubricatedChip& lubricant) {
  LubricantRecord l;
  l.fluid_dofs = 3 * lubricant.fluid().space().node_count();
  for (const auto& h : lubricant.history()) {
    l.coupling_iterations += h.coupling_iterations;
    l.coupling_restarts += h.coupling_restarts;
    l.max_coupling_iterations = std::max(l.max_coupling_iterations, h.coupling_iterations);
    l.fluid_newton_iterations += h.fluid_newton_iterations;
    l.leaked_area += h.leaked_area;
    l.exchanged_area += h.exchanged_area;
    l.min_relative_jacobian = std::min(l.min_relative_jacobian, h.min_relative_jacobian);
  }
  l.initial_film_area = lubricant.formed_film_area();
  l.initial_liquid_area = lubricant.formed_liquid_area();
  if (!lubricant.history().empty()) {
    l.final_film_area = lubricant.history().back().film_area;
    l.final_liquid_area = lubricant.history().back().liquid_area;
    l.final_pocket_areas = lubricant.history().back().pocket_areas;
  }
  return l;
}

// The chip's state at the end: contact, the extremes over its quadrature points, and a warning when
// any of them reached the melting temperature (μ is then outside what the model describes).
void record_end_state(const Scene& scene, const solid::SolidProblem& problem, const contact::ContactState& last,
                      MicroResult& result) {
  result.contact_fraction = last.surface_length > 0.0 ? last.contact_length / last.surface_length : 0.0;
  result.max_contact_pressure = last.max_pressure;
  result.final_contact = last;
  int molten = 0;
  for (const auto& s : problem.states()) {
    result.max_plastic_strain = std::max(result.max_plastic_strain, s.equivalent_plastic_strain);
    result.max_temperature = std::max(result.max_temperature, s.temperature);
    molten += s.temperature >= scene.material.melting_temperature;
  }
  if (molten > 0) {
    result.warnings.push_back("the chip reached its melting temperature (" +
                              format_human(scene.material.melting_temperature, QuantityKind::temperature) + ") at " +
                              std::to_string(molten) + " of " + std::to_string(problem.states().size()) +
                              " quadrature points: Johnson-Cook leaves it no strength there, so mu is outside the model's range");
  }
}

// μ over the window, or why there is none; and its work split.
void record_outcome(const Scene& scene, const StepRecorder& recorder, MicroResult& result) {
  const WindowAverage& average = recorder.average();
  if (!result.solver.completed) {
    result.reason = explain_stop(scene, result.solver.reason);
  } else if (average.weight() <= 0.0) {
    result.reason = "the chip did not touch the tool during the averaging window; raise load.pressure or lower "
                    "geometry.initial_gap";
  } else {
    result.completed = true;
    result.mu = average.mean();
    if (scene.protocol.name != Protocol::seed000) {
      result.block_means = average.block_means();
      result.drift = (result.block_means.back() - result.block_means.front()) / std::max(std::abs(result.mu), 1e-300);
    }
    if (recorder.interface_average().weight() > 0.0) result.mu_interface_work = recorder.interface_average().mean();
    if (recorder.plastic_average().weight() > 0.0) result.mu_plastic_work = recorder.plastic_average().mean();
    if (recorder.normal_average().weight() > 0.0) result.mu_normal_work = recorder.normal_average().mean();
  }
}

}  // namespace

std::string explain_stop(const Scene& scene, const std::string& reason) {
  const bool sealed_incompressible = scene.physics == Physics::lubricated && scene.lubricant.leak == coupling::LeakModel::none &&
                                     scene.lubricant.compressibility == coupling::Compressibility::none;
  if (!sealed_incompressible || !coupling::is_interface_failure(reason)) return reason;
  // Küttler, Förster & Wall 2006 (Comput. Mech. 38:417): a Dirichlet-Neumann iteration around an
  // enclosed incompressible fluid cannot converge, since no chip motion but one of zero volume fits it.
  return reason +
         " (the film is sealed and incompressible: most likely a pocket enclosed by the contact, whose liquid "
         "admits no motion of the chip that changes its volume; --set lubricant.compressibility=linear gives the "
         "oil its bulk modulus, --set lubricant.leak=ambient lets it drain)";
}

MicroResult run_micro(const Scene& scene, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const SceneGeometry geometry = build_geometry(scene);
  const BottomMotion motion(scene);
  LoadedChip chip = load_chip(scene, geometry, motion);
  solid::SolidProblem& problem = *chip.problem;
  MicroResult result;
  result.dofs = problem.dof_count();
  result.elements = problem.space().element_count();
  result.slide_start_time = motion.slide_start();

  solid::TimeIntegrationOptions o = integration_options(scene, motion);
  WallTimeLimit limit(options);
  limit.watch_failed_attempts(o);
  const auto heat = add_heat_conduction(scene, chip, o);
  const auto lubricant = add_lubricant(scene, problem, geometry, motion, o);
  if (lubricant && scene.contact.interface.law->frictional()) chip.point_states->attach_lubricant(lubricant.get(), chip.contact.get());
  solid::TimeIntegrator integrator(problem, o);
  if (scene.protocol.name == Protocol::seed000 && scene.time.scheme == solid::TimeScheme::generalized_alpha) {
    // The chip starts moving with Γ_B: a rigid translation at the sliding velocity.
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(problem.dof_count());
    for (Eigen::Index i = 0; i < v0.size(); i += 2) v0(i) = scene.velocity;
    integrator.set_initial(Eigen::VectorXd::Zero(problem.dof_count()), v0);
  }
  StepRecorder recorder(scene, motion, *chip.contact, lubricant.get());
  result.solver = integrator.run([&](const solid::StepView& view) {
    const MicroStep& step = recorder.record(view);
    chip.point_states->latch();  // after the step's own record: the next step's k, T and wetted spots
    if (options.on_step) options.on_step(step, scene);
    limit.check_accepted_step(step, recorder.history().size());
  });
  limit.check_report(result.solver);

  result.history = std::move(recorder.history());
  for (size_t k = 0; k < result.solver.steps.size() && k < result.history.size(); ++k) {
    result.history[k].newton_iterations = result.solver.steps[k].newton_iterations;
  }
  result.averaged_steps = recorder.average().steps();
  if (lubricant) result.lubricant = lubricant_record(*lubricant);
  record_end_state(scene, problem, recorder.last_contact(), result);
  record_outcome(scene, recorder, result);
  if (!options.vtu_directory.empty()) {
    write_chip_vtu(options.vtu_directory + "/chip.vtu", problem, integrator.u(), recorder.last_contact());
    write_tool_vtu(options.vtu_directory + "/tool.vtu", geometry.tool_surface);
    write_contact_csv(options.vtu_directory + "/contact.csv", recorder.last_contact());
    if (lubricant) write_film_vtu(options.vtu_directory + "/film.vtu", lubricant->fluid());
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace mufric::run
