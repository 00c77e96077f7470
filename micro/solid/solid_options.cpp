#include "micro/solid/solid_options.hpp"

namespace mufric::solid {

JohnsonCookParameters read_johnson_cook(OptionKeys& m, const JohnsonCookParameters& defaults) {
  JohnsonCookParameters p = defaults;
  p.youngs_modulus = m.quantity("youngs_modulus", QuantityKind::pressure, p.youngs_modulus, 1e6, 1e13);
  p.poisson_ratio = m.number("poisson_ratio", p.poisson_ratio, -0.99, 0.499);
  p.density = m.number("density", p.density, 1.0, 1e5);
  p.a = m.quantity("a", QuantityKind::pressure, p.a, 1.0, 1e11);
  p.b = m.quantity("b", QuantityKind::pressure, p.b, 0.0, 1e11);
  p.c = m.number("c", p.c, 0.0, 10.0);
  p.n = m.number("n", p.n, 0.0, 5.0);
  p.m = m.number("m", p.m, 0.01, 10.0);
  p.reference_strain_rate = m.number("reference_strain_rate", p.reference_strain_rate, 1e-12, 1e12);
  p.transition_temperature = m.quantity("transition_temperature", QuantityKind::temperature, p.transition_temperature, 0.0, 1e4);
  p.melting_temperature = m.quantity("melting_temperature", QuantityKind::temperature, p.melting_temperature, 1.0, 1e4);
  if (!(p.melting_temperature > p.transition_temperature)) m.fail("melting_temperature", "must exceed transition_temperature");
  p.specific_heat = m.number("specific_heat", p.specific_heat, 1.0, 1e5);
  p.heat_fraction = m.number("heat_fraction", p.heat_fraction, 0.0, 1.0);
  return p;
}

ChipDiscretisation ChipDiscretisation::read(OptionKeys& d) {
  ChipDiscretisation o;
  o.degree = d.integer("degree", o.degree, 1, 6);
  o.elements_x = d.integer("elements_x", o.elements_x, 4, 100000);
  o.elements_y = d.integer("elements_y", o.elements_y, 1, 100000);
  o.grading = d.number("grading", o.grading, 1.0, 6.0);
  o.volumetric = d.choice("volumetric", o.volumetric);
  o.contact_points_per_span = d.integer("contact_points_per_span", o.contact_points_per_span, 0, 20);
  return o;
}

ChipMeshOptions ChipDiscretisation::mesh(double chip_height) const {
  return {.degree = degree, .spans_x = elements_x, .spans_y = elements_y, .y_bottom = -chip_height, .grading = grading};
}

TimeOptions TimeOptions::read(OptionKeys& t) {
  TimeOptions o;
  o.scheme = t.choice("scheme", o.scheme);
  o.spectral_radius = t.number("spectral_radius", o.spectral_radius, 0.0, 1.0);
  o.dt = t.quantity("step", QuantityKind::time, o.dt, 1e-15, 1.0);
  o.max_dt = t.quantity("max_step", QuantityKind::time, o.dt, 1e-15, 1.0);
  if (o.max_dt < o.dt) t.fail("max_step", "is shorter than time.step");
  return o;
}

NewtonOptions NewtonOptions::read(OptionKeys& v) {
  NewtonOptions o;
  o.relative_tolerance = v.number("relative_tolerance", o.relative_tolerance, 1e-15, 1e-2);
  o.max_newton_iterations = v.integer("max_newton_iterations", o.max_newton_iterations, 1, 1000);
  o.max_cutbacks = v.integer("max_cutbacks", o.max_cutbacks, 0, 40);
  o.linear_solver = v.choice("linear_solver", o.linear_solver);
  return o;
}

TimeIntegrationOptions integration_options(const TimeOptions& time, const NewtonOptions& newton) {
  TimeIntegrationOptions o;
  o.scheme = time.scheme;
  o.spectral_radius = time.spectral_radius;
  o.dt = time.dt;
  o.max_dt = time.max_dt;
  o.relative_tolerance = newton.relative_tolerance;
  o.max_newton_iterations = newton.max_newton_iterations;
  o.max_cutbacks = newton.max_cutbacks;
  o.linear_solver = newton.linear_solver;
  return o;
}

ThermalOptions ThermalOptions::read(OptionKeys& h, ThermalModel model_default) {
  ThermalOptions o;
  o.model = h.choice("model", model_default);
  o.conductivity = h.number("conductivity", o.conductivity, 0.0, 1e4);
  return o;
}

HeatConductionOptions heat_conduction_options(const ThermalOptions& thermal, const JohnsonCookParameters& material,
                                              double held_temperature) {
  return {.conductivity = thermal.conductivity,
          .density = material.density,
          .specific_heat = material.specific_heat,
          .held_side = numerics::Side::bottom,
          .held_temperature = held_temperature};
}

}  // namespace mufric::solid
