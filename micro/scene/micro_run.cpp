#include "micro/scene/micro_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>

#include <omp.h>

#include "common/environment.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "common/version.hpp"
#include "common/work_pool.hpp"
#include "micro/coupling/lubricated_chip.hpp"
#include "micro/coupling/partitioned.hpp"
#include "micro/scene/vtu.hpp"
#include "micro/solid/heat_conduction.hpp"

namespace mufric::scene {
namespace {

// Samples per interval when placing the tool over the chip: finer than any fitted span.
constexpr int kPlacementSamples = 8192;

spline::SplineCurve surface_curve(const SurfaceSpec& spec, double interval, const std::string& what) {
  spline::Profile profile;
  if (spec.flat) {
    const int m = std::max(4 * spec.control_points, 64);
    profile.period = interval;
    profile.source = what + " (flat)";
    for (int k = 0; k < m; ++k) {
      profile.x.push_back(interval * k / m);
      profile.height.push_back(0.0);
    }
  } else if (!spec.csv.empty()) {
    profile = spline::read_profile_csv(spec.csv, interval);
  } else {
    spline::RoughnessSpec r = spec.synthetic;
    r.length = interval;
    profile = spline::synthetic_rough_profile(r);
  }
  if (spec.mirror) {
    const double x0 = profile.x.front();
    std::reverse(profile.x.begin(), profile.x.end());
    std::reverse(profile.height.begin(), profile.height.end());
    for (double& x : profile.x) x = 2.0 * x0 + interval - x;
  }
  if (spec.control_points >= static_cast<int>(profile.x.size())) {
    throw Error(what + ": fit.control_points (" + std::to_string(spec.control_points) + ") must be below the " +
                std::to_string(profile.x.size()) + " samples of the profile");
  }
  spline::SplineCurve curve = spline::fit_periodic_profile(profile, spec.degree, spec.control_points).curve;
  if (spec.shift_fraction != 0.0) {
    spline::Points2 moved = curve.points();
    moved.col(0).array() += spec.shift_fraction * interval;
    curve = spline::SplineCurve(curve.basis(), moved, curve.weights(), curve.shift());
  }
  return curve;
}

// Heights of a periodic curve on a uniform grid of x over one interval (linear interpolation
// between dense samples of the curve; the profiles are graphs over x).
std::vector<double> heights_on_grid(const spline::SplineCurve& c, double interval, int samples) {
  std::vector<std::pair<double, double>> xy;
  for (int k = 0; k < samples; ++k) {
    const Eigen::Vector2d p = c.point(static_cast<double>(k) / samples);
    xy.emplace_back(p.x() - std::floor(p.x() / interval) * interval, p.y());
  }
  std::sort(xy.begin(), xy.end());
  std::vector<double> out(static_cast<size_t>(samples));
  size_t j = 0;
  for (int g = 0; g < samples; ++g) {
    const double x = interval * g / samples;
    while (j < xy.size() && xy[j].first <= x) ++j;
    const auto& right = j < xy.size() ? xy[j] : std::make_pair(xy.front().first + interval, xy.front().second);
    const auto& left = j > 0 ? xy[j - 1] : std::make_pair(xy.back().first - interval, xy.back().second);
    const double t = right.first > left.first ? (x - left.first) / (right.first - left.first) : 0.0;
    out[static_cast<size_t>(g)] = left.second + t * (right.second - left.second);
  }
  return out;
}

double ramp(double t, double ramp_time) { return ramp_time > 0.0 ? std::min(t / ramp_time, 1.0) : 1.0; }

}  // namespace

SceneGeometry build_geometry(const Scene& scene) {
  const spline::SplineCurve chip = surface_curve(scene.chip_surface, scene.interval, scene.source + ": chip_surface");
  spline::SplineCurve tool = surface_curve(scene.tool_surface, scene.interval, scene.source + ": tool_surface");
  const auto chip_h = heights_on_grid(chip, scene.interval, kPlacementSamples);
  const auto tool_h = heights_on_grid(tool, scene.interval, kPlacementSamples);
  double closest = std::numeric_limits<double>::infinity();
  for (size_t g = 0; g < chip_h.size(); ++g) closest = std::min(closest, tool_h[g] - chip_h[g]);
  spline::Points2 raised = tool.points();
  raised.col(1).array() += scene.initial_gap - closest;
  tool = spline::SplineCurve(tool.basis(), raised, tool.weights(), tool.shift());
  return {chip, tool};
}

namespace {

// What every result file starts with: provenance (for a file of its own), the outcome and μ.
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

}  // namespace

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

// Where Γ_B is and how far it has slid, for the scene's protocol.
class BottomMotion {
 public:
  explicit BottomMotion(const Scene& scene) : velocity_(scene.velocity) {
    if (scene.protocol.name == Protocol::seed000) return;
    const ProtocolSpec& q = scene.protocol;
    const double speed = std::abs(velocity_);
    slide_start_ = scene.ramp + q.press_hold;
    acceleration_time_ = 2.0 * kAccelerationShareOfRunIn * q.run_in / speed;
    end_time_ = slide_start_ + 0.5 * acceleration_time_ + (q.run_in + q.window) / speed;
  }
  // Horizontal displacement of Γ_B at t: v t (seed 000: no pressing, no acceleration), or held
  // during pressing, then a linear rise of the velocity to v over acceleration_time_, then v.
  double displacement(double t) const {
    const double s = t - slide_start_;
    if (s <= 0.0) return 0.0;
    if (s < acceleration_time_) return velocity_ * s * s / (2.0 * acceleration_time_);
    return velocity_ * (s - 0.5 * acceleration_time_);
  }
  double distance(double t) const { return std::abs(displacement(t)); }
  double slide_start() const { return slide_start_; }
  double end_time() const { return end_time_; }

 private:
  double velocity_;
  double slide_start_ = 0.0, acceleration_time_ = 0.0, end_time_ = 0.0;
};

// μ averaged over a window of "position" (time for seed 000, sliding distance for press-slide),
// the value at the end of each step standing for the step's whole segment, and over equal blocks.
class WindowAverage {
 public:
  // blocks = 0: no block means (the window may then be unbounded)
  WindowAverage(double from, double to, int blocks) : from_(from), to_(to), sums_(static_cast<size_t>(blocks), 0.0) {}
  void add(double position_before, double position_after, double mu) {
    const double a = std::max(position_before, from_), b = std::min(position_after, to_);
    if (!(b > a)) return;
    sum_ += mu * (b - a);
    weight_ += b - a;
    ++steps_;
    if (sums_.empty()) return;
    const double block = (to_ - from_) / static_cast<double>(sums_.size());
    for (size_t k = 0; k < sums_.size(); ++k) {
      const double lo = from_ + block * static_cast<double>(k), hi = lo + block;
      const double overlap = std::min(b, hi) - std::max(a, lo);
      if (overlap > 0.0) sums_[k] += mu * overlap;
    }
  }
  double weight() const { return weight_; }
  double mean() const { return sum_ / weight_; }
  int steps() const { return steps_; }
  std::vector<double> block_means() const {
    std::vector<double> means;
    const double block = (to_ - from_) / static_cast<double>(sums_.size());
    for (double s : sums_) means.push_back(s / block);
    return means;
  }

 private:
  double from_, to_;
  double sum_ = 0.0, weight_ = 0.0;
  int steps_ = 0;
  std::vector<double> sums_;
};

}  // namespace

namespace {

coupling::LubricantOptions lubricant_options(const Scene& scene, double slide_start) {
  const LubricantSpec& l = scene.lubricant;
  coupling::LubricantOptions o;
  o.fluid = {l.density, l.viscosity, l.compressibility == Compressibility::none ? 0.0 : l.bulk_modulus,
             l.compressibility == Compressibility::dowson_higginson ? fluid::kDowsonHigginsonStiffening : 0.0};
  o.mesh.degree = 2;  // equal-order quadratic velocity and pressure
  o.mesh.elements_x = l.elements_x > 0 ? l.elements_x : scene.elements_x;
  o.mesh.elements_y = l.elements_y;
  o.mesh.min_film = l.min_film;
  o.mesh_motion = l.mesh_motion;
  o.mesh_update.stiffening_exponent = l.mesh_stiffening;
  o.robin_weight = l.robin_weight;
  o.robin_stiffness = l.robin_stiffness;
  o.chip_mass_per_area = scene.material.density * scene.chip_height;
  o.shortest_weight_step = scene.dt;
  o.film_from = l.fill == FilmFill::after_pressing ? slide_start : 0.0;
  o.contact_fade = l.contact_fade;
  if (l.leak != LeakModel::none) o.leak = l.leak == LeakModel::ambient ? fluid::LeakTarget::ambient : fluid::LeakTarget::mean;
  o.leak_length = l.leak_length;
  if (l.cavitation == CavitationModel::mass_conserving) o.cavitation_pressure = l.cavitation_pressure;
  o.coupling.acceleration = l.acceleration;
  o.coupling.relaxation = l.relaxation;
  o.coupling.reuse_steps = l.reuse_steps;
  o.coupling.qr_filter = l.qr_filter;
  o.coupling.relative_tolerance = l.coupling_tolerance;
  if (scene.pressure_controlled && l.traction_tolerance > 0.0) {
    o.coupling.load_tolerance = l.traction_tolerance * std::abs(scene.pressure);
  }
  o.coupling.kinematic_tolerance = l.volume_tolerance;
  o.coupling.max_iterations = l.max_coupling_iterations;
  o.coupling.stall_iterations = l.stall_iterations;
  o.coupling.max_restarts = l.coupling_restarts;
  return o;
}

// The chip under its loads: the IGA patch fitted to the chip surface, Johnson–Cook at the scene's
// temperature, mortar contact with the rigid tool, and Γ_B dragged along x (at the sliding velocity
// from t = 0 for seed 000; after pressing for press-slide) and pushed toward the tool by p (or moved
// by a prescribed vertical displacement), the vertical load ramped over `ramp`.
struct LoadedChip {
  std::unique_ptr<solid::SolidProblem> problem;
  std::shared_ptr<contact::MortarContact> contact;
  // The contact points' state beyond their pressure, for the interface law: the chip's k and T
  // beneath each point and whether the lubricant wets it, refreshed after every accepted step.
  std::shared_ptr<contact::SampledPointStates> point_states;
  // For the laws that use the chip's state: the bulk quadrature point nearest each contact surface
  // point (reference positions), whose state gives k and T there.
  std::vector<size_t> surface_quadrature;
};

// The chip's state at each contact surface point, from the committed state of its nearest bulk
// quadrature point: k = σ_JC(ε̄ᵖ, ε̇ᵖ, T)/√3 (von Mises) and T, for the laws that use them (they see
// the last accepted state's).
void refresh_chip_state_at_contact(const Scene& scene, const LoadedChip& chip) {
  if (chip.surface_quadrature.empty()) return;
  const auto& states = chip.problem->states();
  std::vector<double> k, temperature;
  k.reserve(chip.surface_quadrature.size());
  temperature.reserve(chip.surface_quadrature.size());
  for (const size_t q : chip.surface_quadrature) {
    const auto& st = states[q];
    k.push_back(solid::johnson_cook_yield_stress(scene.material, st.equivalent_plastic_strain, st.plastic_strain_rate,
                                                 st.temperature) /
                std::sqrt(3.0));
    temperature.push_back(st.temperature);
  }
  const contact::PointStateNeeds needs = scene.contact_interface.law->needs();
  if (needs.shear_strength) chip.point_states->set_shear_strength(std::move(k));
  if (needs.temperature) chip.point_states->set_temperature(std::move(temperature));
}

// The contact points the lubricant wets after the last accepted step (their current positions in
// `contact`, that step's state), for the law's wetted coefficients in the next step — lagged a step
// like k and T. A frictionless law has none: its points report no wetted spot.
void refresh_wetted_contact(const Scene& scene, const LoadedChip& chip, const coupling::LubricatedChip* lubricant,
                            const contact::ContactState& contact) {
  if (lubricant == nullptr || !scene.contact_interface.law->frictional()) return;
  std::vector<char> wetted(contact.point_position.size(), 0);
  for (size_t q = 0; q < wetted.size(); ++q) wetted[q] = lubricant->wetted_at(contact.point_position[q].x()) ? 1 : 0;
  chip.point_states->set_wetted(std::move(wetted));
}

std::vector<size_t> nearest_quadrature_points(const solid::IgaSpace& space, const std::vector<Eigen::Vector2d>& at) {
  std::vector<size_t> nearest;
  nearest.reserve(at.size());
  const auto& quadrature = space.quadrature();
  for (const auto& x : at) {
    size_t best = 0;
    double best_distance = std::numeric_limits<double>::infinity();
    for (size_t q = 0; q < quadrature.size(); ++q) {
      const double d = (quadrature[q].position - x).squaredNorm();
      if (d < best_distance) {
        best_distance = d;
        best = q;
      }
    }
    nearest.push_back(best);
  }
  return nearest;
}

LoadedChip load_chip(const Scene& scene, const SceneGeometry& geometry, const BottomMotion& motion) {
  const auto fit_spans = static_cast<int>(geometry.chip_surface.basis().breakpoints().size()) - 1;
  if (scene.elements_x < fit_spans) {
    throw Error(scene.source + ": discretisation.elements_x (" + std::to_string(scene.elements_x) +
                ") must be at least the chip surface fit's " + std::to_string(fit_spans) + " spans");
  }
  const spline::SplineSurface patch =
      solid::chip_patch(geometry.chip_surface, {.degree = scene.degree,
                                                .spans_x = scene.elements_x,
                                                .spans_y = scene.elements_y,
                                                .y_bottom = -scene.chip_height,
                                                .grading = scene.grading});
  solid::MaterialState initial;
  initial.temperature = scene.temperature;
  LoadedChip chip;
  chip.problem = std::make_unique<solid::SolidProblem>(solid::IgaSpace(patch),
                                                       std::make_shared<solid::J2JohnsonCook>(scene.material), initial,
                                                       scene.volumetric);
  solid::SolidProblem& problem = *chip.problem;
  chip.contact = std::make_shared<contact::MortarContact>(problem.space(), contact::RigidTool{geometry.tool_surface},
                                                          scene.penalty, scene.contact_points_per_span,
                                                          scene.contact_interface);
  chip.point_states = std::make_shared<contact::SampledPointStates>(chip.contact->surface_positions().size(),
                                                                    std::abs(scene.velocity));
  chip.contact->set_point_states(chip.point_states);
  problem.add_interaction(chip.contact);
  if (scene.contact_interface.law->needs().any()) {
    chip.surface_quadrature = nearest_quadrature_points(problem.space(), chip.contact->surface_positions());
    refresh_chip_state_at_contact(scene, chip);
  }
  const double velocity = scene.velocity, ramp_time = scene.ramp;
  if (scene.protocol.name == Protocol::seed000) {
    problem.fix_side(numerics::Side::bottom, 0, velocity, [](double t) { return t; });
  } else {
    problem.fix_side(numerics::Side::bottom, 0, 1.0, [motion](double t) { return motion.displacement(t); });
  }
  if (scene.pressure_controlled) {
    problem.add_load({numerics::Side::bottom, Eigen::Vector2d::Zero(), scene.pressure,
                      [ramp_time](double t) { return ramp(t, ramp_time); }});
  } else {
    problem.fix_side(numerics::Side::bottom, 1, scene.vertical_displacement,
                     [ramp_time](double t) { return ramp(t, ramp_time); });
  }
  return chip;
}

// The scene's time-integration choices, and the protocol's step lengths.
solid::TimeIntegrationOptions integration_options(const Scene& scene, const BottomMotion& motion) {
  const bool seed000 = scene.protocol.name == Protocol::seed000;
  solid::TimeIntegrationOptions o;
  o.scheme = scene.scheme;
  o.spectral_radius = scene.spectral_radius;
  o.dt = scene.dt;
  o.max_dt = scene.max_dt;
  o.end_time = seed000 ? scene.duration : motion.end_time();
  o.relative_tolerance = scene.relative_tolerance;
  o.max_newton_iterations = scene.max_newton_iterations;
  o.max_cutbacks = scene.max_cutbacks;
  o.linear_solver = scene.linear_solver;
  if (!seed000) {
    // Once sliding, steps are sized by distance: inertia plays no part at these sliding speeds
    // (an asperity passes in ~100 ns, the chip's slowest mode rings at ~5 ns), so slow sliding
    // costs no more steps than fast sliding.
    const double sliding_step = scene.protocol.step_distance / std::abs(scene.velocity);
    const double pressing_step = scene.max_dt, slide_start = motion.slide_start();
    o.max_dt_at = [=](double t) { return t < slide_start ? pressing_step : sliding_step; };
  }
  return o;
}

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

// Heat conduction through the chip, staggered after every accepted mechanical step (the plastic work
// and the frictional heat raise the quadrature points' temperature; conduction spreads it).
std::unique_ptr<solid::HeatConduction> add_heat_conduction(const Scene& scene, const LoadedChip& chip,
                                                           solid::TimeIntegrationOptions& o) {
  solid::SolidProblem& problem = *chip.problem;
  if (!scene.heat_conduction()) return nullptr;
  auto heat = std::make_unique<solid::HeatConduction>(
      problem.space(), solid::HeatConductionOptions{.conductivity = scene.conductivity,
                                                    .density = scene.material.density,
                                                    .specific_heat = scene.material.specific_heat,
                                                    .held_side = numerics::Side::bottom,
                                                    .held_temperature = scene.temperature});
  const bool frictional = scene.contact_interface.law->frictional();
  o.after_step = [&problem, conduction = heat.get(), contact = chip.contact.get(), frictional](
                     double, double dt, const Eigen::VectorXd& u, std::string& reason) {
    std::vector<solid::MaterialState> states = problem.states();
    const Eigen::VectorXd friction_heat = frictional ? contact->frictional_heat(problem.space().node_count()) : Eigen::VectorXd();
    if (!conduction->step(u, dt, states, reason, friction_heat)) return false;
    problem.commit(std::move(states));
    return true;
  };
  return heat;
}

// The lubricant: its load joins the chip's boundary interactions before the integrator assembles,
// and every step becomes its fluid–structure exchange.
std::unique_ptr<coupling::LubricatedChip> add_lubricant(const Scene& scene, solid::SolidProblem& problem,
                                                        const SceneGeometry& geometry, const BottomMotion& motion,
                                                        solid::TimeIntegrationOptions& o) {
  if (scene.physics != Physics::lubricated) return nullptr;
  auto lubricant = std::make_unique<coupling::LubricatedChip>(problem, geometry.tool_surface,
                                                              lubricant_options(scene, motion.slide_start()));
  o.coupled_step = [film = lubricant.get()](solid::TimeIntegrator& integrator, double t0, double dt,
                                            std::string& reason) { return film->step(integrator, t0, dt, reason); };
  return lubricant;
}

// What every accepted step records: the contact state, the lubricant's own record of the step, μ by
// eq. (17) over the whole chip boundary (contact and fluid traction), and μ into the window average
// (seed 000 averages over time, press-slide over sliding distance); and the step's interfacial
// dissipation and plastic work per unit sliding distance and normal force into averages over the
// same window (μ's split into its adhesive and ploughing parts).
class StepRecorder {
 public:
  StepRecorder(const Scene& scene, const BottomMotion& motion, const contact::MortarContact& contact,
               const coupling::LubricatedChip* lubricant)
      : seed000_(scene.protocol.name == Protocol::seed000),
        material_(scene.material),
        motion_(motion),
        contact_(contact),
        lubricant_(lubricant),
        // (Seed 000's window has no upper end: the run stops at its end, and the arithmetic stays the
        // one that gave the published figures, to the bit.)
        average_(window(scene)),
        interface_average_(window(scene)),
        plastic_average_(window(scene)),
        normal_average_(window(scene)) {}

  const MicroStep& record(const solid::StepView& view) {
    last_contact_ = contact_.state(view.u);
    MicroStep step;
    step.time = view.time;
    step.sliding_distance = motion_.distance(view.time);
    step.force = last_contact_.force;
    if (lubricant_ && !lubricant_->history().empty()) {
      step.lubricant = lubricant_->history().back();
      step.force += step.lubricant->fluid_force;
    }
    if (step.force.y() != 0.0) step.mu = step.force.x() / step.force.y();  // eq. (17)
    step.contact_fraction = last_contact_.contact_length / last_contact_.surface_length;
    if (last_contact_.contact_length > 0.0) {
      step.wetted_contact_fraction = last_contact_.wetted_contact_length / last_contact_.contact_length;
    }
    step.max_pressure = last_contact_.max_pressure;
    step.interface_dissipation = contact_.dissipated_energy();
    step.plastic_work = plastic_work_ += step_plastic_work(view.problem);
    step.bottom_rise = bottom_rise(view);
    if (step.mu) average_.add(position(previous_time_), position(view.time), *step.mu);
    const double slid = step.sliding_distance - motion_.distance(previous_time_);
    if (slid > 0.0 && step.force.y() != 0.0) {
      const double per_slid_load = 1.0 / (slid * std::abs(step.force.y()));
      const double previous_dissipation = history_.empty() ? 0.0 : history_.back().interface_dissipation;
      interface_average_.add(position(previous_time_), position(view.time),
                             (step.interface_dissipation - previous_dissipation) * per_slid_load);
      const double previous_work = history_.empty() ? 0.0 : history_.back().plastic_work;
      plastic_average_.add(position(previous_time_), position(view.time), (step.plastic_work - previous_work) * per_slid_load);
      const double previous_rise = history_.empty() ? 0.0 : history_.back().bottom_rise;
      normal_average_.add(position(previous_time_), position(view.time), (step.bottom_rise - previous_rise) / slid);
    }
    previous_time_ = view.time;
    history_.push_back(std::move(step));
    return history_.back();
  }
  std::vector<MicroStep>& history() { return history_; }
  const WindowAverage& average() const { return average_; }
  const WindowAverage& interface_average() const { return interface_average_; }
  const WindowAverage& plastic_average() const { return plastic_average_; }
  const WindowAverage& normal_average() const { return normal_average_; }
  const contact::ContactState& last_contact() const { return last_contact_; }

 private:
  static WindowAverage window(const Scene& scene) {
    if (scene.protocol.name == Protocol::seed000) {
      return WindowAverage(scene.average_from, std::numeric_limits<double>::infinity(), 0);
    }
    return WindowAverage(scene.protocol.run_in, scene.protocol.run_in + scene.protocol.window, scene.protocol.blocks);
  }
  // Σ_q w_q σ_y Δε̄ᵖ over the step (σ_y, the Kirchhoff yield stress of the return map, at the end of
  // the step: the backward-Euler plastic work of the J2 model).
  double step_plastic_work(const solid::SolidProblem& problem) {
    const auto& states = problem.states();
    const auto& qps = problem.space().quadrature();
    if (plastic_strain_.empty()) plastic_strain_.assign(states.size(), 0.0);
    double work = 0.0;
    for (size_t q = 0; q < states.size(); ++q) {
      const auto& st = states[q];
      const double increment = st.equivalent_plastic_strain - plastic_strain_[q];
      if (increment <= 0.0) continue;
      work += qps[q].weight * increment *
              solid::johnson_cook_yield_stress(material_, st.equivalent_plastic_strain, st.plastic_strain_rate, st.temperature);
      plastic_strain_[q] = st.equivalent_plastic_strain;
    }
    return work;
  }
  // The mean vertical displacement of Γ_B (the chip's bottom, pushed toward the tool along +y).
  static double bottom_rise(const solid::StepView& view) {
    const std::vector<int> nodes = view.problem.space().side_nodes(numerics::Side::bottom);
    double sum = 0.0;
    for (const int a : nodes) sum += view.u(2 * a + 1);
    return nodes.empty() ? 0.0 : sum / static_cast<double>(nodes.size());
  }
  double position(double t) const { return seed000_ ? t : motion_.distance(t); }
  bool seed000_;
  const solid::JohnsonCookParameters& material_;
  const BottomMotion& motion_;
  const contact::MortarContact& contact_;
  const coupling::LubricatedChip* lubricant_;
  WindowAverage average_, interface_average_, plastic_average_, normal_average_;
  contact::ContactState last_contact_;
  std::vector<double> plastic_strain_;  // ε̄ᵖ per quadrature point at the last record
  double plastic_work_ = 0.0;
  double previous_time_ = 0.0;
  std::vector<MicroStep> history_;
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
  const bool sealed_incompressible = scene.physics == Physics::lubricated && scene.lubricant.leak == LeakModel::none &&
                                     scene.lubricant.compressibility == Compressibility::none;
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
  solid::TimeIntegrator integrator(problem, o);
  if (scene.protocol.name == Protocol::seed000 && scene.scheme == solid::TimeScheme::generalized_alpha) {
    // The chip starts moving with Γ_B: a rigid translation at the sliding velocity.
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(problem.dof_count());
    for (Eigen::Index i = 0; i < v0.size(); i += 2) v0(i) = scene.velocity;
    integrator.set_initial(Eigen::VectorXd::Zero(problem.dof_count()), v0);
  }
  StepRecorder recorder(scene, motion, *chip.contact, lubricant.get());
  result.solver = integrator.run([&](const solid::StepView& view) {
    const MicroStep& step = recorder.record(view);
    refresh_chip_state_at_contact(scene, chip);  // after the step's own record: the next step's k and T
    refresh_wetted_contact(scene, chip, lubricant.get(), recorder.last_contact());  // and its wetted spots
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

std::vector<Draw> protocol_draws(const Scene& scene) {
  if (scene.protocol.name == Protocol::seed000) return {Draw{0, 0, 0.0, scene.tool_surface.synthetic.seed, {}, {}}};
  std::vector<Draw> draws;
  const int phases = scene.protocol.phases, realisations = scene.protocol.realisations;
  const bool chip_drawn = scene.protocol.draws == DrawnSurfaces::tools_and_chip;
  for (int r = 0; r < realisations; ++r) {
    const auto offset = static_cast<std::uint64_t>(r);
    for (int k = 0; k < phases; ++k) {
      Draw d{k, r, static_cast<double>(k) / phases, scene.tool_surface.synthetic.seed + offset, {}, {}};
      if (chip_drawn) d.chip_seed = scene.chip_surface.synthetic.seed + offset;
      draws.push_back(d);
    }
  }
  return draws;
}

Scene draw_scene(const Scene& scene, const Draw& draw) {
  Scene s = scene;
  // A shift by a whole interval is no shift: keep the fraction in [0, 1).
  const double shift = scene.tool_surface.shift_fraction + draw.shift_fraction;
  s.tool_surface.shift_fraction = shift - std::floor(shift);
  s.tool_surface.synthetic.seed = draw.seed;
  if (draw.chip_seed) s.chip_surface.synthetic.seed = *draw.chip_seed;
  return s;
}

MeasurementTotals MuMeasurement::totals() const {
  MeasurementTotals t;
  for (const auto& d : draws) {
    t.newton_iterations += d.result.solver.newton_iterations;
    t.cutbacks += static_cast<int>(d.result.solver.cutbacks.size());
    if (d.result.lubricant) t.coupling_iterations += d.result.lubricant->coupling_iterations;
    t.max_contact_pressure = std::max(t.max_contact_pressure, d.result.max_contact_pressure);
    t.max_plastic_strain = std::max(t.max_plastic_strain, d.result.max_plastic_strain);
    t.max_temperature = std::max(t.max_temperature, d.result.max_temperature);
    t.contact_fraction += d.result.contact_fraction / static_cast<double>(draws.size());
    t.draw_seconds_sum += d.result.wall_seconds;
  }
  if (!draws.empty()) t.dofs = draws.front().result.dofs;
  return t;
}

namespace {

constexpr std::pair<const char*, int MeasurementTotals::*> kTotalsCounts[] = {
    {"newton_iterations", &MeasurementTotals::newton_iterations},
    {"coupling_iterations", &MeasurementTotals::coupling_iterations},
    {"cutbacks", &MeasurementTotals::cutbacks},
    {"dofs", &MeasurementTotals::dofs}};
constexpr std::pair<const char*, double MeasurementTotals::*> kTotalsValues[] = {
    {"max_contact_pressure_pa", &MeasurementTotals::max_contact_pressure},
    {"max_plastic_strain", &MeasurementTotals::max_plastic_strain},
    {"max_temperature_k", &MeasurementTotals::max_temperature},
    {"contact_area_fraction", &MeasurementTotals::contact_fraction}};

}  // namespace

nlohmann::json MeasurementTotals::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, field] : kTotalsCounts) j[name] = this->*field;
  for (const auto& [name, field] : kTotalsValues) j[name] = this->*field;
  return j;
}

std::map<std::string, double> MeasurementTotals::named_values() const {
  std::map<std::string, double> values;
  for (const auto& [name, field] : kTotalsCounts) values[name] = static_cast<double>(this->*field);
  for (const auto& [name, field] : kTotalsValues) values[name] = this->*field;
  return values;
}

double MuMeasurement::max_abs_drift() const {
  double d = 0.0;
  for (const auto& draw : draws) d = std::max(d, std::abs(draw.result.drift));
  return d;
}

void add_measurement_advisories(MuMeasurement& m) {
  const double n = static_cast<double>(m.draws.size());
  for (size_t i = 0; i < m.draws.size(); ++i) {
    const double drift = m.draws[i].result.drift;
    if (std::abs(drift) > kDriftWarningFraction) {
      char text[256];
      std::snprintf(text, sizeof text,
                    "draw %zu: mu drifted by %.1f %% of mu across its averaging window (first to last block mean, "
                    "warning above %.0f %%): the slide may not be steady; a longer protocol.window or more draws",
                    i, 100.0 * drift, 100.0 * kDriftWarningFraction);
      m.advisories.emplace_back(text);
    }
  }
  if (m.draws.size() > 1 && m.draws.size() < kFewDrawsForStdError) {
    // The relative standard error of a sample standard deviation from n draws is ≈ 1/√(2(n − 1))
    // (normal draws; Kendall & Stuart, The Advanced Theory of Statistics, Vol. 1, §10.8).
    char text[256];
    std::snprintf(text, sizeof text,
                  "the standard error of mu comes from %zu draws: it is itself uncertain by about +-%.0f %%; "
                  "%zu or more draws make it a figure to rely on",
                  m.draws.size(), 100.0 / std::sqrt(2.0 * (n - 1.0)), kFewDrawsForStdError);
    m.advisories.emplace_back(text);
  }
}

MuMeasurement measure_mu(const Scene& scene, const MeasureOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MuMeasurement m;
  m.draws = protocol_draws(scene);
  const int cores = std::max(options.threads > 0 ? options.threads : usable_cores(), 1);
  const int workers = std::min(cores, static_cast<int>(m.draws.size()));
  m.threads = workers;
  // Draws are independent runs: one per worker, each worker's OpenMP share of the cores for its
  // assembly (a single draw gets them all).
  const int threads_per_draw = std::max(cores / workers, 1);
  std::mutex progress_lock;
  std::vector<std::string> failures(m.draws.size());
  run_work_pool(m.draws.size(), workers, [&](size_t i) {
    omp_set_num_threads(threads_per_draw);
    RunOptions run;
    if (i == 0) run.vtu_directory = options.vtu_directory;
    if (options.wall_seconds_limit > 0.0) {
      run.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(options.wall_seconds_limit));
      run.wall_seconds_limit = options.wall_seconds_limit;
    }
    if (options.on_step) {
      run.on_step = [&, i](const MicroStep& step, const Scene& sc) {
        const std::lock_guard<std::mutex> lock(progress_lock);
        options.on_step(static_cast<int>(i), step, sc);
      };
    }
    try {
      m.draws[i].result = run_micro(draw_scene(scene, m.draws[i]), run);
    } catch (const std::exception& e) {  // a bad scene fails every draw alike: reported once below
      failures[i] = e.what();
    }
    return true;
  });
  for (size_t i = 0; i < failures.size(); ++i) {
    if (!failures[i].empty()) throw Error(failures[i]);
  }

  std::vector<double> values;
  for (const auto& draw : m.draws) {
    const MicroResult& r = draw.result;
    for (const auto& w : r.warnings) {
      if (std::find(m.warnings.begin(), m.warnings.end(), w) == m.warnings.end()) m.warnings.push_back(w);
    }
    if (!r.completed && m.reason.empty()) {
      m.reason = m.draws.size() == 1 ? r.reason
                                     : "draw " + std::to_string(&draw - m.draws.data()) + " (tool phase " +
                                           std::to_string(draw.phase) + ", realisation " +
                                           std::to_string(draw.realisation) + ") did not complete: " + r.reason;
    }
    values.push_back(r.mu);
  }
  if (m.reason.empty()) {
    m.completed = true;
    const double n = static_cast<double>(values.size());
    m.mu = std::accumulate(values.begin(), values.end(), 0.0) / n;
    if (values.size() > 1) {
      double squares = 0.0;
      for (double x : values) squares += (x - m.mu) * (x - m.mu);
      m.std_error = std::sqrt(squares / (n - 1.0) / n);  // sample standard deviation / √n
    }
    add_measurement_advisories(m);
  }
  m.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m;
}

nlohmann::json MuMeasurement::to_json(const Scene& scene) const {
  std::vector<std::string> all_warnings = warnings;
  all_warnings.insert(all_warnings.end(), advisories.begin(), advisories.end());
  nlohmann::json j = result_head(scene, true, completed, reason, all_warnings, mu);
  j["mu_std_error"] = completed && std_error ? nlohmann::json(*std_error) : nlohmann::json(nullptr);
  const ProtocolSpec& q = scene.protocol;
  nlohmann::json& p = j["protocol"];
  if (q.name == Protocol::seed000) {
    p = {{"name", "seed-000"},
         {"means", "one draw; pressure ramped over load.ramp while sliding; mu averaged over a time window"},
         {"window_s", {scene.average_from, scene.duration}},
         {"draws", draws.size()}};
  } else {
    p = {{"name", "press-slide"},
         {"means", "pressed (ramp, then hold), then slid; mu averaged over a sliding-distance window after a run-in, "
                   "then over the draws (tool phases and realisations, each realisation a new tool and, with drawn_surfaces "
                   "tools-and-chip, a new chip surface); mu_std_error is the standard error of that mean"},
         {"press_ramp_s", scene.ramp},
         {"press_hold_s", q.press_hold},
         {"run_in_m", q.run_in},
         {"window_m", q.window},
         {"window_in_tool_correlation_lengths",
          scene.tool_surface.is_synthetic()
              ? nlohmann::json(q.window / scene.tool_surface.synthetic.correlation_length)
              : nlohmann::json(nullptr)},
         {"step_distance_m", q.step_distance},
         {"phases", q.phases},
         {"realisations", q.realisations},
         {"drawn_surfaces", choice_name(q.draws)},
         {"draws", draws.size()},
         {"max_abs_drift", max_abs_drift()}};
  }
  // Aggregates over the draws, for scripts that read one run.
  const MeasurementTotals t = totals();
  nlohmann::json& diagnostics = j["diagnostics"] = t.to_json();
  diagnostics["wall_seconds"] = wall_seconds;
  diagnostics["threads"] = threads;
  diagnostics["draw_seconds_sum"] = t.draw_seconds_sum;
  diagnostics["elements"] = draws.empty() ? 0 : draws.front().result.elements;
  // The work split, averaged over the draws like μ.
  double interface_sum = 0.0, plastic_sum = 0.0, normal_sum = 0.0;
  int split_draws = 0;
  for (const auto& d : draws) {
    const MicroResult& r = d.result;
    if (!r.mu_interface_work || !r.mu_plastic_work || !r.mu_normal_work) continue;
    interface_sum += *r.mu_interface_work;
    plastic_sum += *r.mu_plastic_work;
    normal_sum += *r.mu_normal_work;
    ++split_draws;
  }
  if (completed && split_draws == static_cast<int>(draws.size()) && split_draws > 0) {
    j["work_split"] = work_split_json(interface_sum / split_draws, plastic_sum / split_draws, normal_sum / split_draws);
  }
  auto& list = j["draws"] = nlohmann::json::array();
  for (const auto& d : draws) {
    nlohmann::json one = d.result.to_json(scene, false);
    one["phase"] = d.phase;
    one["realisation"] = d.realisation;
    one["tool_shift_fraction"] = d.shift_fraction;
    one["tool_seed"] = d.seed;
    one["chip_seed"] = d.chip_seed                        ? nlohmann::json(*d.chip_seed)
                       : scene.chip_surface.is_synthetic() ? nlohmann::json(scene.chip_surface.synthetic.seed)
                                                           : nlohmann::json(nullptr);
    if (!d.result.block_means.empty()) {
      one["block_means"] = d.result.block_means;
      one["drift"] = d.result.drift;
    }
    list.push_back(std::move(one));
  }
  return j;
}

}  // namespace mufric::scene
