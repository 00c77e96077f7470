#include "micro/coupling/lubricant_settings.hpp"

#include <cmath>

namespace mufric::coupling {

LubricantSettings LubricantSettings::read(OptionKeys& f, bool press_slide) {
  LubricantSettings l;
  l.density = f.number("density", l.density, 1.0, 1e5);
  l.viscosity = f.number("viscosity", l.viscosity, 1e-6, 1e6);
  l.compressibility = f.choice("compressibility", l.compressibility);
  l.bulk_modulus = f.quantity("bulk_modulus", QuantityKind::pressure, l.bulk_modulus, 1e6, 1e13);
  l.elements_x = f.integer("elements_x", l.elements_x, 0, 100000);
  l.elements_y = f.integer("elements_y", l.elements_y, 1, 1000);
  l.min_film = f.quantity("min_film", QuantityKind::length, l.min_film, 1e-12, 1e-6);
  l.fill = f.choice("fill", press_slide ? l.fill : FilmFill::gap);
  if (l.fill == FilmFill::after_pressing && !press_slide) {
    f.fail("fill", "after-pressing needs the press-slide protocol (seed 000's presses while sliding)");
  }
  l.cavitation = f.choice("cavitation", l.cavitation);
  l.cavitation_pressure = f.quantity("cavitation_pressure", QuantityKind::pressure, l.cavitation_pressure, -1e9, 1e9);
  l.leak = f.choice("leak", press_slide ? l.leak : LeakModel::none);
  l.leak_length = f.quantity("leak_length", QuantityKind::length, l.leak_length, 1e-9, 1.0);
  l.contact_fade = f.number("contact_fade", l.contact_fade, 1.01, 100.0);
  l.robin_weight = f.number("robin_weight", l.robin_weight, 0.0, 1e30);
  l.robin_stiffness = f.number("robin_stiffness", l.robin_stiffness, 0.0, 1e25);
  l.mesh_motion = f.choice("mesh_motion", l.mesh_motion);
  l.mesh_stiffening = f.number("mesh_stiffening", l.mesh_stiffening, 0.0, 5.0);
  l.acceleration = f.choice("acceleration", l.acceleration);
  l.relaxation = f.number("relaxation", l.relaxation, 1e-6, 1.0);
  l.reuse_steps = f.integer("reuse_steps", l.reuse_steps, 0, 100);
  l.qr_filter = f.number("qr_filter", l.qr_filter, 0.0, 0.999);
  l.coupling_tolerance = f.number("coupling_tolerance", l.coupling_tolerance, 1e-14, 1e-1);
  l.traction_tolerance = f.number("traction_tolerance", l.traction_tolerance, 0.0, 1e-1);
  l.volume_tolerance = f.number("volume_tolerance", l.volume_tolerance, 1e-14, 1.0);
  l.max_coupling_iterations = f.integer("max_coupling_iterations", l.max_coupling_iterations, 1, 10000);
  l.stall_iterations = f.integer("stall_iterations", l.stall_iterations, 0, 10000);
  l.coupling_restarts = f.integer("coupling_restarts", l.coupling_restarts, 0, 100);
  return l;
}

LubricantOptions lubricant_options(const LubricantSettings& l, const LubricantRun& run) {
  LubricantOptions o;
  o.fluid = {l.density, l.viscosity, l.compressibility == Compressibility::none ? 0.0 : l.bulk_modulus,
             l.compressibility == Compressibility::dowson_higginson ? fluid::kDowsonHigginsonStiffening : 0.0};
  o.mesh.degree = 2;  // equal-order quadratic velocity and pressure
  o.mesh.elements_x = l.elements_x > 0 ? l.elements_x : run.chip_elements_x;
  o.mesh.elements_y = l.elements_y;
  o.mesh.min_film = l.min_film;
  o.mesh_motion = l.mesh_motion;
  o.mesh_update.stiffening_exponent = l.mesh_stiffening;
  o.robin_weight = l.robin_weight;
  o.robin_stiffness = l.robin_stiffness;
  o.chip_mass_per_area = run.chip_mass_per_area;
  o.shortest_weight_step = run.first_step;
  o.film_from = l.fill == FilmFill::after_pressing ? run.slide_start : 0.0;
  o.contact_fade = l.contact_fade;
  if (l.leak != LeakModel::none) o.leak = l.leak == LeakModel::ambient ? fluid::LeakTarget::ambient : fluid::LeakTarget::mean;
  o.leak_length = l.leak_length;
  if (l.cavitation == CavitationModel::mass_conserving) o.cavitation_pressure = l.cavitation_pressure;
  o.coupling.acceleration = l.acceleration;
  o.coupling.relaxation = l.relaxation;
  o.coupling.reuse_steps = l.reuse_steps;
  o.coupling.qr_filter = l.qr_filter;
  o.coupling.relative_tolerance = l.coupling_tolerance;
  if (run.applied_pressure && l.traction_tolerance > 0.0) o.coupling.load_tolerance = l.traction_tolerance * std::abs(*run.applied_pressure);
  o.coupling.kinematic_tolerance = l.volume_tolerance;
  o.coupling.max_iterations = l.max_coupling_iterations;
  o.coupling.stall_iterations = l.stall_iterations;
  o.coupling.max_restarts = l.coupling_restarts;
  return o;
}

}  // namespace mufric::coupling
