#include "micro/coupling/lubricated_chip.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/environment.hpp"
#include "common/error.hpp"

namespace mufric::coupling {

using fluid::Side;

namespace {

// MUFRIC_TRACE_COUPLING=1 prints every coupled step's interface residuals to stderr (diagnosing a run).
bool trace_coupling() {
  static const bool on = environment_flag("MUFRIC_TRACE_COUPLING");
  return on;
}

}  // namespace

double robin_weight(const LubricantOptions& options, double dt) {
  if (options.robin_weight > 0.0) return options.robin_weight;
  // Backward Euler on ρh v̇ + β d = −σn gives (ρh/Δt + βΔt) v = −σn + …: the structure's own Robin
  // relation (Badia, Nobile & Vergara 2008), with Δt no shorter than the scene's base step.
  return options.chip_mass_per_area / std::max(dt, options.shortest_weight_step) + options.robin_stiffness * dt;
}

LubricatedChip::LubricatedChip(solid::SolidProblem& problem, const spline::SplineCurve& tool, LubricantOptions options)
    : problem_(problem), tool_curve_(tool), options_(std::move(options)), mesh_update_(options_.mesh_update),
      accelerator_(options_.coupling) {
  if (!(options_.contact_fade > 1.0)) throw Error("lubricant: the contact fade must span more than one minimum film");
  if (options_.leak && !(options_.leak_length > 0.0)) throw Error("lubricant: the leak length must be positive");
  if (!(options_.robin_weight > 0.0) && !(options_.chip_mass_per_area > 0.0 && options_.shortest_weight_step > 0.0)) {
    throw Error("lubricant: give a Robin weight, or the chip's mass per area and the shortest step for the automatic one");
  }
  surface_ = std::make_unique<ChipSurface>(problem_.space());
  const auto& tb = tool_curve_.basis();
  tool_ = std::make_unique<PeriodicGraph>([this](double t) { return tool_curve_.point(t); }, tb.lo(), tb.period(),
                                          8 * tb.count());
  if (options_.cavitation_pressure) cavitation_.emplace(*options_.cavitation_pressure, options_.leak.has_value());
  load_ = std::make_shared<NodalLoad>(problem_.dof_count());
  problem_.add_interaction(load_);
  form_film();
  if (!(options_.film_from > 0.0)) {
    film_formed_ = true;
    formed_film_area_ = fluid_->space().area();
    formed_liquid_area_ = liquid_area();
  }
}

void LubricatedChip::form_film() {
  fluid::NavierStokesOptions ns;
  ns.fluid = options_.fluid;
  fluid_ = std::make_unique<fluid::NavierStokes>(fluid::FluidSpace(gap_patch(surface_->graph(), *tool_, 0.0, options_.mesh)), ns);
  bottom_nodes_ = fluid_->space().side_nodes(Side::bottom);
  top_nodes_.clear();
  bottom_parameters_.clear();
  top_nodes_ = fluid_->space().side_nodes(Side::top);
  for (const auto& p : fluid_->space().side_points(Side::bottom)) bottom_parameters_.push_back(p.u);
  traction_ = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(bottom_parameters_.size()));
  normal_stress_.assign(bottom_parameters_.size(), 0.0);
  opening_rate_.assign(bottom_parameters_.size(), 0.0);
  if (cavitation_) cavitation_->form(film_samples());  // the contact spots' minimum layer holds no liquid
}

size_t LubricatedChip::sample_at(double parameter) const {
  const auto& p = bottom_parameters_;
  const auto it = std::lower_bound(p.begin(), p.end(), parameter - 1e-12 * (p.back() - p.front()));
  return static_cast<size_t>(std::min<std::ptrdiff_t>(it - p.begin(), static_cast<std::ptrdiff_t>(p.size()) - 1));
}

bool LubricatedChip::wetted_at(double x) const {
  if (wetted_.empty()) return false;
  // The film's columns stand at x = u over one period [lo, hi): the nearest sample to x wrapped into it.
  const auto& basis = fluid_->space().patch().u_basis();
  const double lo = basis.lo(), period = basis.hi() - basis.lo();
  const double u = lo + std::fmod(std::fmod(x - lo, period) + period, period);
  const auto& p = bottom_parameters_;
  const auto right = static_cast<size_t>(std::lower_bound(p.begin(), p.end(), u) - p.begin());
  const size_t n = p.size();
  const size_t after = right % n, before = (right + n - 1) % n;
  const auto distance = [&](size_t q) {
    const double d = std::abs(p[q] - u);
    return std::min(d, period - d);
  };
  return wetted_[distance(before) <= distance(after) ? before : after] != 0;
}

std::vector<FilmSample> LubricatedChip::film_samples() const {
  const fluid::FluidSpace& space = fluid_->space();
  const auto& points = space.side_points(Side::bottom);
  std::vector<FilmSample> samples;
  samples.reserve(points.size());
  const Side bottom = Side::bottom;
  for (size_t q = 0; q < points.size(); ++q) {
    const double film = film_thickness(points[q]);
    // The parametric weight is the width along x (the columns are at x = u), the mapped one the wall's length.
    samples.push_back({film, points[q].weight, space.map(points[q], &bottom).weight,
                       film < options_.contact_fade * options_.mesh.min_film, normal_stress_[q], opening_rate_[q]});
  }
  return samples;
}

double LubricatedChip::film_thickness(const fluid::ParametricPoint& bottom_point) const {
  // The film's columns do not move along x, so the top point above is at the same u.
  const fluid::FluidSpace& space = fluid_->space();
  const double top = space.patch().v_basis().hi();
  return space.map(space.at(bottom_point.u, top)).position.y() - space.map(bottom_point).position.y();
}

void LubricatedChip::update_leak() {
  if (!options_.leak) return;
  const auto& points = fluid_->space().side_points(Side::bottom);
  leak_coefficients_.resize(points.size());
  // The columns do not move along x, so every point of the film at the parameter u of a bottom Gauss
  // point is in that point's column: the film is h thick there. A cavitated column holds a cavity (a
  // contact spot's layer holds no liquid at all): no liquid leaves it, or the books would count the
  // same space twice — as cavity and as leaked liquid (the liquid went negative at 1300 MPa).
  for (size_t q = 0; q < points.size(); ++q) {
    leak_coefficients_[q] = cavitation_ && cavitation_->cavitated(q)
                                ? 0.0
                                : fluid::out_of_plane_leak_coefficient(film_thickness(points[q]), options_.fluid.viscosity,
                                                                       options_.leak_length);
  }
  fluid_->set_leak({[this](const Eigen::Vector2d&, double u) { return leak_coefficients_[sample_at(u)]; }, 0.0, *options_.leak});
}

double LubricatedChip::liquid_area() const {
  return fluid_->space().area() - (cavitation_ ? cavitation_->cavity_area() : 0.0);
}

double LubricatedChip::contact_share(double film) const {
  // At a contact spot (the film at its minimum) the contact carries the chip; the fluid's share
  // fades out linearly between contact_fade and one minimum film, so that the transferred
  // load is continuous in the chip's position (a switch would make the coupling's map jump).
  const double h = options_.mesh.min_film;
  return std::clamp((film - h) / ((options_.contact_fade - 1.0) * h), 0.0, 1.0);
}

Eigen::VectorXd LubricatedChip::load_share() const {
  const auto& points = fluid_->space().side_points(Side::bottom);
  Eigen::VectorXd share(2 * static_cast<Eigen::Index>(points.size()));
  for (size_t q = 0; q < points.size(); ++q) {
    share.segment<2>(2 * static_cast<Eigen::Index>(q)).setConstant(contact_share(film_thickness(points[q])));
  }
  return share;
}

Eigen::VectorXd LubricatedChip::transfer(const Eigen::VectorXd& traction) const {
  const fluid::FluidSpace& space = fluid_->space();
  const auto& points = space.side_points(Side::bottom);
  std::vector<Eigen::Vector2d> positions, loads;
  std::vector<double> weights;
  for (size_t q = 0; q < points.size(); ++q) {
    const Side bottom = Side::bottom;
    const fluid::PhysicalPoint at = space.map(points[q], &bottom);
    const double share = contact_share(film_thickness(points[q]));
    if (share == 0.0) continue;
    positions.push_back(at.position);
    loads.push_back(-share * traction.segment<2>(2 * static_cast<Eigen::Index>(q)));  // the chip receives −σn
    weights.push_back(at.weight);
  }
  return surface_->nodal_forces(positions, loads, weights);
}

bool LubricatedChip::structure(solid::TimeIntegrator& integrator, double t0, double dt, const Eigen::VectorXd& traction,
                               Eigen::VectorXd& displacement, std::string& reason) {
  load_->set(transfer(traction));
  if (!integrator.solve_trial(t0, dt, reason)) return false;
  const Eigen::VectorXd& u = integrator.trial_u();
  surface_->update(u, integrator.trial_v());
  const std::vector<int> chip_top = problem_.space().side_nodes(Side::top);
  displacement.resize(2 * static_cast<Eigen::Index>(chip_top.size()));
  for (size_t i = 0; i < chip_top.size(); ++i) displacement.segment<2>(2 * static_cast<Eigen::Index>(i)) = u.segment<2>(2 * chip_top[i]);
  return true;
}

fluid::MeshMoveReport LubricatedChip::move_film_mesh(const Eigen::MatrixX2d& rows) {
  fluid::FluidSpace& space = fluid_->space();
  if (options_.mesh_motion == FilmMeshMotion::columns) {
    // Each column's points spaced across the film as when it formed (gap_net).
    const Eigen::MatrixX2d net = gap_net(space.patch(), rows);
    Eigen::VectorXd displacement = space.displacement();
    for (int node = 0; node < space.node_count(); ++node) {
      displacement.segment<2>(2 * node) += net.row(node).transpose() - space.node_position(node);
    }
    return fluid::place_mesh(space, displacement);
  }
  std::vector<std::pair<int, Eigen::Vector2d>> prescribed;
  const auto n = static_cast<Eigen::Index>(bottom_nodes_.size());
  for (Eigen::Index i = 0; i < n; ++i) {
    const int b = bottom_nodes_[static_cast<size_t>(i)], t = top_nodes_[static_cast<size_t>(i)];
    prescribed.emplace_back(b, rows.row(i).transpose() - space.node_position(b));
    prescribed.emplace_back(t, rows.row(n + i).transpose() - space.node_position(t));
  }
  return mesh_update_.move(space, prescribed);
}

bool LubricatedChip::film(const Eigen::VectorXd&, const Eigen::VectorXd& traction, double dt, Eigen::VectorXd& new_traction,
                          std::string& reason) {
  fluid::FluidSpace& space = fluid_->space();
  space.set_displacement(mesh_start_);
  const fluid::MeshMoveReport moved = move_film_mesh(gap_boundary_rows(space.patch(), surface_->graph(), *tool_, options_.mesh));
  if (!moved.ok) {
    reason = moved.reason;
    return false;
  }
  update_leak();
  const double alpha = robin_weight(options_, dt);
  // The film's wall moves with the chip along the surface and with the film mesh's bottom across it:
  // that bottom interpolates the chip's surface at the columns, so the chip's own normal velocity
  // would move liquid through the film's boundary by that interpolation; the wall's keeps the film's
  // volume to the coupling's tolerance.
  const ChipSurface* chip = surface_.get();
  const Eigen::VectorXd mesh_velocity = (space.displacement() - mesh_start_) / dt;
  const double bottom_v = space.patch().v_basis().lo();
  const fluid::BoundaryField wall_velocity = [chip, &space, &mesh_velocity, bottom_v](const Eigen::Vector2d& x, double u) {
    const Eigen::Vector2d g = chip->velocity(chip->parameter_at(x.x()));
    const Side bottom = Side::bottom;
    const fluid::ParametricPoint p = space.at(u, bottom_v);
    const Eigen::Vector2d normal = space.map(p, &bottom).normal;
    const Eigen::Vector2d wall = fluid::FluidSpace::interpolate2(p, mesh_velocity, 2, 0);
    return Eigen::Vector2d(g + (wall - g).dot(normal) * normal);
  };
  const fluid::BoundaryField previous = [this, &traction](const Eigen::Vector2d&, double t) {
    return Eigen::Vector2d(traction.segment<2>(2 * static_cast<Eigen::Index>(sample_at(t))));
  };
  // Where the film has cavitated the liquid no longer follows the chip: a traction side at p_c.
  const fluid::BoundaryScalar follows_chip = [this](const Eigen::Vector2d&, double t) {
    return cavitation_ && cavitation_->cavitated(sample_at(t)) ? 0.0 : 1.0;
  };
  // The tool stands still, but where the chip presses into it the film's top is lifted to keep the
  // minimum film above the chip: the top moves with its mesh (which is still on the tool elsewhere),
  // so the film's volume changes only as its walls move (the mesh velocity is in the velocity's space:
  // the prescribed flux is the top's own).
  const double top_v = space.patch().v_basis().hi();
  const fluid::BoundaryField tool_velocity = [&space, &mesh_velocity, top_v](const Eigen::Vector2d&, double u) {
    return fluid::FluidSpace::interpolate2(space.at(u, top_v), mesh_velocity, 2, 0);
  };
  fluid_->set_mesh(space.displacement(), mesh_velocity);
  fluid_->set_conditions({{Side::top, fluid::SideConditionKind::velocity, tool_velocity, {}, 0.0},
                          {Side::bottom, fluid::SideConditionKind::robin, wall_velocity, previous, alpha, follows_chip}});
  const fluid::FluidStepReport r = fluid_->solve_step(dt);
  current_.fluid_newton_iterations += r.newton_iterations;
  current_.min_relative_jacobian = std::min(current_.min_relative_jacobian, r.min_relative_jacobian);
  if (!r.converged) {
    reason = "lubricant: " + r.reason;
    return false;
  }
  const auto samples = fluid_->robin_traction(Side::bottom);
  new_traction.resize(2 * static_cast<Eigen::Index>(samples.size()));
  // The volume this step's mismatch of the interface velocities moves through the film's wall, over
  // the film's (a cavity's area follows the wall by itself: only full samples count). Over the
  // liquid's the liquid drifted 1.3 % instead of 10 % on the study run, at twice the exchanges, and
  // the box centre stopped (RESULTS, "The lubricant, fifth pass").
  double created = 0.0;
  for (size_t q = 0; q < samples.size(); ++q) {
    const Eigen::Vector2d& normal = samples[q].normal;
    normal_stress_[q] = samples[q].traction.dot(normal);
    opening_rate_[q] = (wall_velocity(samples[q].position, samples[q].parameter) - samples[q].velocity).dot(normal);
    const bool cavitated = cavitation_ && cavitation_->cavitated(q);
    new_traction.segment<2>(2 * static_cast<Eigen::Index>(q)) =
        cavitated ? Eigen::Vector2d(-cavitation_->cavitation_pressure() * normal) : samples[q].traction;
    if (!cavitated) created += samples[q].weight * opening_rate_[q] * dt;
  }
  mismatch_area_ = created;
  volume_error_ = std::abs(created) / space.area();
  return true;
}

bool LubricatedChip::step(solid::TimeIntegrator& integrator, double t0, double dt, std::string& reason) {
  if (t0 < options_.film_from * (1.0 - 1e-12)) return integrator.solve_trial(t0, dt, reason);  // dry until the film forms
  if (!film_formed_) {
    surface_->update(integrator.u(), integrator.v());
    form_film();
    accelerator_.forget_past_steps();
    film_formed_ = true;
    formed_film_area_ = fluid_->space().area();
    formed_liquid_area_ = liquid_area();
  }
  current_ = LubricatedStep();
  // The fixed-point map depends on the step length (the chip's inertia per step): secant pairs of
  // steps of another length would mislead IQN-ILS.
  if (dt != last_accepted_dt_) accelerator_.forget_past_steps();
  fluid_->begin_step();
  const Eigen::VectorXd fluid_start = fluid_->state();
  mesh_start_ = fluid_->space().displacement();
  const PartitionedSolvers solvers{
      [&](const Eigen::VectorXd& traction, Eigen::VectorXd& d, std::string& why) {
        return structure(integrator, t0, dt, traction, d, why);
      },
      [&](const Eigen::VectorXd& d, const Eigen::VectorXd& traction, Eigen::VectorXd& next, std::string& why) {
        return film(d, traction, dt, next, why);
      },
      [&] { return volume_error_; },
      [&] { return load_share(); }};
  Eigen::VectorXd traction = traction_, displacement;
  CouplingStepReport report;
  try {
    report = coupled_step(solvers, traction, displacement, accelerator_, options_.coupling);
  } catch (const Error& e) {
    // A trial the interface cannot follow (e.g. a chip surface folded by a wild iterate) fails the
    // step, which is then cut back, like any other failure inside it.
    report.converged = false;
    report.reason = e.what();
  }
  current_.coupling_iterations = report.iterations;
  current_.coupling_restarts = report.restarts;
  if (trace_coupling()) {
    std::fprintf(stderr, "coupling t %.4g dt %.3g: %s after %d, %d restarts (fluid Newton %d, cavitated %.3f%s)\n", t0 + dt,
                 dt, report.converged ? "converged" : "failed", current_.coupling_iterations, report.restarts,
                 current_.fluid_newton_iterations, cavitation_ ? cavitation_->cavitated_fraction() : 0.0,
                 surface_->graph().folded() ? ", chip surface folded" : "");
    for (size_t k = 0; k < report.load_residuals.size(); ++k) {
      std::fprintf(stderr, "  |dlambda| %.4e Pa  |dd| %.4e m  film volume error %.3e\n", report.load_residuals[k],
                   report.displacement_changes[k], report.kinematic_residuals[k]);
    }
  }
  if (!report.converged) {
    // Back to the start of the step for the cut-back's retry.
    fluid_->set_state(fluid_start);
    fluid_->set_mesh(mesh_start_, Eigen::VectorXd::Zero(mesh_start_.size()));
    reason = "lubricant coupling: " + report.reason;
    return false;
  }
  traction_ = traction;
  last_accepted_dt_ = dt;
  const Eigen::VectorXd& f = load_->forces();
  for (Eigen::Index a = 0; a < f.size(); a += 2) current_.fluid_force += f.segment<2>(a);
  current_.film_area = fluid_->space().area();
  current_.volume_error = volume_error_;
  current_.leaked_area = fluid_->leak_rate() * dt;
  current_.exchanged_area = fluid_->leak_exchange_rate() * dt;
  const std::vector<FilmSample> samples = film_samples();
  current_.pocket_areas = pocket_areas(samples);
  if (cavitation_) {
    // Where the film is cavitated in the next step, from this step's liquid.
    cavitation_->update(samples, dt);
    current_.cavitated_fraction = cavitation_->cavitated_fraction();
    current_.cavity_area = cavitation_->cavity_area();
    if (trace_coupling()) {
      std::fprintf(stderr, "  liquid %.6e m2/m: full samples' mismatch %.4e, closing overshoot %.4e, lost %.4e, cavity overgrowth %.4e\n",
                   liquid_area(), mismatch_area_, cavitation_->closing_overshoot(), cavitation_->lost_overshoot(),
                   cavitation_->overgrowth());
    }
  }
  current_.liquid_area = liquid_area();
  std::vector<char> liquid_at_wall(samples.size(), 1);
  for (size_t q = 0; q < samples.size(); ++q) liquid_at_wall[q] = cavitation_ && cavitation_->cavitated(q) ? 0 : 1;
  wetted_ = wetted_spots(samples, liquid_at_wall);
  history_.push_back(current_);
  return true;
}

std::vector<double> LubricatedChip::pocket_areas(const std::vector<FilmSample>& samples) {
  if (std::none_of(samples.begin(), samples.end(), [](const FilmSample& f) { return f.spot; })) return {};
  std::vector<double> areas;
  for (const auto& run : pocket_runs(samples)) {
    double area = 0.0;
    for (size_t q : run) area += samples[q].film * samples[q].width;
    areas.push_back(area);
  }
  return areas;
}

}  // namespace mufric::coupling
