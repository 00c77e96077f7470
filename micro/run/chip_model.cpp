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

ChipPointStates::ChipPointStates(const solid::SolidProblem& problem, std::vector<size_t> surface_quadrature,
                                 double sliding_velocity, contact::PointStateNeeds needs)
    : problem_(problem), surface_quadrature_(std::move(surface_quadrature)), sliding_velocity_(sliding_velocity), needs_(needs) {
  latch();
}

contact::ContactPointState ChipPointStates::state(size_t point) const {
  if (point < latched_.size()) return latched_[point];
  contact::ContactPointState s;
  s.sliding_velocity = sliding_velocity_;
  return s;
}

std::optional<std::string> ChipPointStates::missing(const contact::PointStateNeeds&) const { return std::nullopt; }

void ChipPointStates::attach_lubricant(const coupling::LubricatedChip* lubricant, const contact::MortarContact* contact) {
  lubricant_ = lubricant;
  contact_ = contact;
}

void ChipPointStates::latch() {
  const bool wetting = lubricant_ != nullptr && !contact_->committed_positions().empty();
  const size_t points = std::max(surface_quadrature_.size(), wetting ? contact_->committed_positions().size() : size_t{0});
  latched_.assign(points, contact::ContactPointState{.sliding_velocity = sliding_velocity_});
  const auto& states = problem_.states();
  for (size_t q = 0; q < surface_quadrature_.size(); ++q) {
    const solid::MaterialState& at = states[surface_quadrature_[q]];
    if (needs_.shear_strength) latched_[q].shear_strength = problem_.material().shear_yield_stress(at);
    if (needs_.temperature) latched_[q].temperature = at.temperature;
  }
  if (wetting) {
    for (size_t q = 0; q < points; ++q) latched_[q].wetted = lubricant_->wetted_at(contact_->committed_positions()[q].x());
  }
}

LoadedChip load_chip(const Scene& scene, const SceneGeometry& geometry, const BottomMotion& motion) {
  const auto fit_spans = static_cast<int>(geometry.chip_surface.basis().breakpoints().size()) - 1;
  if (scene.discretisation.elements_x < fit_spans) {
    throw Error(scene.source + ": discretisation.elements_x (" + std::to_string(scene.discretisation.elements_x) +
                ") must be at least the chip surface fit's " + std::to_string(fit_spans) + " spans");
  }
  const spline::SplineSurface patch =
      solid::chip_patch(geometry.chip_surface, scene.discretisation.mesh(scene.chip_height));
  solid::MaterialState initial;
  initial.temperature = scene.temperature;
  initial.equivalent_plastic_strain = scene.initial_plastic_strain;
  LoadedChip chip;
  chip.problem = std::make_unique<solid::SolidProblem>(solid::IgaSpace(patch),
                                                       std::make_shared<solid::J2JohnsonCook>(scene.material), initial,
                                                       scene.discretisation.volumetric);
  solid::SolidProblem& problem = *chip.problem;
  chip.contact = std::make_shared<contact::MortarContact>(problem.space(), contact::RigidTool{geometry.tool_surface},
                                                          scene.contact.penalty, scene.discretisation.contact_points_per_span,
                                                          scene.contact.interface);
  const contact::PointStateNeeds needs = scene.contact.interface.law->needs();
  chip.point_states = std::make_shared<ChipPointStates>(
      problem, needs.any() ? nearest_quadrature_points(problem.space(), chip.contact->surface_positions()) : std::vector<size_t>{},
      std::abs(scene.velocity), needs);
  chip.contact->set_point_states(chip.point_states);
  problem.add_interaction(chip.contact);
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
  solid::TimeIntegrationOptions o = solid::integration_options(scene.time, scene.newton);
  o.end_time = seed000 ? scene.duration : motion.end_time();
  if (!seed000) {
    // Once sliding, steps are sized by distance: inertia plays no part at these sliding speeds
    // (an asperity passes in ~100 ns, the chip's slowest mode rings at ~5 ns), so slow sliding
    // costs no more steps than fast sliding.
    const double sliding_step = scene.protocol.step_distance / std::abs(scene.velocity);
    const double pressing_step = scene.time.max_dt, slide_start = motion.slide_start();
    o.max_dt_at = [=](double t) { return t < slide_start ? pressing_step : sliding_step; };
  }
  return o;
}

std::unique_ptr<solid::HeatConduction> add_heat_conduction(const Scene& scene, const LoadedChip& chip,
                                                           solid::TimeIntegrationOptions& o) {
  solid::SolidProblem& problem = *chip.problem;
  if (!scene.thermal.conducts()) return nullptr;
  auto heat = std::make_unique<solid::HeatConduction>(
      problem.space(), solid::heat_conduction_options(scene.thermal, scene.material, scene.temperature));
  const bool frictional = scene.contact.interface.law->frictional();
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
  const coupling::LubricantRun run{
      .chip_elements_x = scene.discretisation.elements_x,
      .chip_mass_per_area = scene.material.density * scene.chip_height,
      .first_step = scene.time.dt,
      .slide_start = motion.slide_start(),
      .applied_pressure = scene.pressure_controlled ? std::optional<double>(scene.pressure) : std::nullopt};
  auto lubricant = std::make_unique<coupling::LubricatedChip>(problem, geometry.tool_surface,
                                                              coupling::lubricant_options(scene.lubricant, run));
  o.coupled_step = [film = lubricant.get()](solid::TimeIntegrator& integrator, double t0, double dt,
                                            std::string& reason) { return film->step(integrator, t0, dt, reason); };
  return lubricant;
}

}  // namespace mufric::run
