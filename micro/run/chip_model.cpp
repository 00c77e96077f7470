#include "micro/run/chip_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"

namespace mufric::run {
using namespace scene;
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

void refresh_wetted_contact(const Scene& scene, const LoadedChip& chip, const coupling::LubricatedChip* lubricant,
                            const contact::ContactState& contact) {
  if (lubricant == nullptr || !scene.contact_interface.law->frictional()) return;
  std::vector<char> wetted(contact.point_position.size(), 0);
  for (size_t q = 0; q < wetted.size(); ++q) wetted[q] = lubricant->wetted_at(contact.point_position[q].x()) ? 1 : 0;
  chip.point_states->set_wetted(std::move(wetted));
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

}  // namespace mufric::run
