#include "micro/scene/micro_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "common/error.hpp"
#include "common/units.hpp"
#include "common/version.hpp"
#include "micro/scene/vtu.hpp"

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

nlohmann::json MicroResult::to_json(const Scene& scene) const {
  nlohmann::json j;
  j["code_version"] = code_version();
  j["created_utc"] = utc_timestamp();
  j["scene"] = scene.effective;
  j["completed"] = completed;
  if (!completed) j["reason"] = reason;
  j["warnings"] = warnings;
  j["mu"] = completed ? nlohmann::json(mu) : nlohmann::json(nullptr);
  j["mu_window_s"] = {scene.average_from, scene.duration};
  j["averaged_steps"] = averaged_steps;
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
                      {"assembly_seconds", solver.seconds_assembly},
                      {"contact_seconds", solver.seconds_contact},
                      {"solve_seconds", solver.seconds_solve}};
  auto& cuts = j["cutbacks"] = nlohmann::json::array();
  for (const auto& c : solver.cutbacks) cuts.push_back({{"time_s", c.time}, {"dt_failed_s", c.dt_failed}, {"reason", c.reason}});
  auto& h = j["history"] = nlohmann::json::array();
  for (const auto& s : history) {
    h.push_back({{"time_s", s.time},
                 {"mu", s.mu ? nlohmann::json(*s.mu) : nlohmann::json(nullptr)},
                 {"force_x_n_per_m", s.force.x()},
                 {"force_y_n_per_m", s.force.y()},
                 {"contact_area_fraction", s.contact_fraction},
                 {"max_contact_pressure_pa", s.max_pressure},
                 {"newton_iterations", s.newton_iterations}});
  }
  return j;
}

MicroResult run_micro(const Scene& scene, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MicroResult result;
  const SceneGeometry geometry = build_geometry(scene);
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
  solid::SolidProblem problem(solid::IgaSpace(patch), std::make_shared<solid::J2JohnsonCook>(scene.material), initial);
  auto contact = std::make_shared<contact::MortarContact>(problem.space(), contact::RigidTool{geometry.tool_surface},
                                                          scene.penalty, scene.contact_points_per_span);
  problem.add_interaction(contact);
  // Γ_B: dragged along x at the sliding velocity, pushed toward the tool by p (or moved by a
  // prescribed vertical displacement), both vertical loads ramped over `ramp`.
  const double velocity = scene.velocity, ramp_time = scene.ramp;
  problem.fix_side(solid::Side::bottom, 0, velocity, [](double t) { return t; });
  if (scene.pressure_controlled) {
    problem.add_load({solid::Side::bottom, Eigen::Vector2d::Zero(), scene.pressure,
                      [ramp_time](double t) { return ramp(t, ramp_time); }});
  } else {
    problem.fix_side(solid::Side::bottom, 1, scene.vertical_displacement,
                     [ramp_time](double t) { return ramp(t, ramp_time); });
  }
  result.dofs = problem.dof_count();
  result.elements = problem.space().element_count();

  solid::TimeIntegrationOptions o;
  o.scheme = scene.scheme;
  o.spectral_radius = scene.spectral_radius;
  o.dt = scene.dt;
  o.max_dt = scene.max_dt;
  o.end_time = scene.duration;
  o.relative_tolerance = scene.relative_tolerance;
  o.max_newton_iterations = scene.max_newton_iterations;
  o.max_cutbacks = scene.max_cutbacks;
  o.linear_solver = scene.linear_solver;
  solid::TimeIntegrator integrator(problem, o);
  if (scene.scheme == solid::TimeScheme::generalized_alpha) {
    // The chip starts moving with Γ_B: a rigid translation at the sliding velocity.
    Eigen::VectorXd v0 = Eigen::VectorXd::Zero(problem.dof_count());
    for (Eigen::Index i = 0; i < v0.size(); i += 2) v0(i) = velocity;
    integrator.set_initial(Eigen::VectorXd::Zero(problem.dof_count()), v0);
  }
  contact::ContactState last;
  double weighted_mu = 0.0, weight = 0.0, previous_time = 0.0;
  result.solver = integrator.run([&](const solid::StepView& view) {
    last = contact->state(view.u);
    MicroStep step;
    step.time = view.time;
    step.force = last.force;
    if (last.force.y() != 0.0) step.mu = last.force.x() / last.force.y();  // eq. (17)
    step.contact_fraction = last.contact_length / last.surface_length;
    step.max_pressure = last.max_pressure;
    result.history.push_back(step);
    if (step.mu && view.time > scene.average_from) {
      const double dt = view.time - std::max(previous_time, scene.average_from);
      weighted_mu += *step.mu * dt;
      weight += dt;
      ++result.averaged_steps;
    }
    previous_time = view.time;
    if (options.on_step) options.on_step(step, scene);
  });
  const solid::IntegrationReport& report = result.solver;
  for (size_t k = 0; k < report.steps.size() && k < result.history.size(); ++k) {
    result.history[k].newton_iterations = report.steps[k].newton_iterations;
  }
  result.contact_fraction = last.surface_length > 0.0 ? last.contact_length / last.surface_length : 0.0;
  result.max_contact_pressure = last.max_pressure;
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
  if (!report.completed) {
    result.reason = report.reason;
  } else if (weight <= 0.0) {
    result.reason = "the chip did not touch the tool during the averaging window; raise load.pressure or lower "
                    "geometry.initial_gap";
  } else {
    result.completed = true;
    result.mu = weighted_mu / weight;
  }
  if (!options.vtu_directory.empty()) {
    write_chip_vtu(options.vtu_directory + "/chip.vtu", problem, integrator.u(), last);
    write_tool_vtu(options.vtu_directory + "/tool.vtu", geometry.tool_surface);
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace mufric::scene
