#pragma once
// The solid module's options as a scene states them, each with its defaults (the micro-model's, from
// the studies in bench/RESULTS.md), its reader (micro/settings/option_keys.hpp: ranges, units, the
// checks between its own keys) and what the module makes of them. The scene only composes these
// (micro/scene/scene.hpp); an option of the solid is added here and nowhere else.
#include "micro/settings/option_keys.hpp"
#include "micro/solid/heat_conduction.hpp"
#include "micro/solid/iga_space.hpp"
#include "micro/solid/materials.hpp"
#include "micro/solid/solid_problem.hpp"
#include "micro/solid/time_integrator.hpp"

namespace mufric::solid {

// Defaults below are written as a scene file's units compute them (scale × value, as parse_quantity
// does: "1ns" is 1e-9 × 1), so that a file stating a default reads to the very same double.
constexpr double nanoseconds(double x) { return 1e-9 * x; }

// material: Johnson–Cook and the thermal constants (seed 000 Table 1), over `defaults`.
JohnsonCookParameters read_johnson_cook(OptionKeys& keys, const JohnsonCookParameters& defaults = {});

// discretisation: the chip's IGA patch, its volumetric treatment and the contact's points on it.
struct ChipDiscretisation {
  int degree = 2;
  int elements_x = 64;
  int elements_y = 12;
  double grading = 2.0;  // spans across the height shrink toward the surface: v_k = 1 − (1 − k/n)^grading
  // full: the displacement formulation (seed 000's); mean-dilatation: F-bar (solid_problem.hpp)
  VolumetricTreatment volumetric = VolumetricTreatment::full;
  int contact_points_per_span = 0;  // 0: degree + 3
  static ChipDiscretisation read(OptionKeys& keys);
  // The patch of a chip of this height under `surface`.
  ChipMeshOptions mesh(double chip_height) const;
  bool operator==(const ChipDiscretisation&) const = default;
};

// time: the time integration's scheme and steps.
struct TimeOptions {
  TimeScheme scheme = TimeScheme::generalized_alpha;
  // ρ∞ 0.5: damps the chip's thickness vibration that the pressure ramp excites, which with 0.8 still
  // rang through the averaging window, and gave μ closest to the small-step runs (bench/studies/dry_micro_model/README.md).
  double spectral_radius = 0.5;
  double dt = nanoseconds(1);  // s, the first step
  double max_dt = dt;          // s, the longest step the step-size control may take (absent: time.step)
  // Reads scheme, spectral_radius, step and max_step; leaves the section's other keys to its other readers.
  static TimeOptions read(OptionKeys& keys);
  bool operator==(const TimeOptions&) const = default;
};

// solver: Newton's tolerances and the linear solver.
struct NewtonOptions {
  double relative_tolerance = 1e-9;
  int max_newton_iterations = 30;
  int max_cutbacks = 8;
  // Cholesky by default: frictionless penalty contact, associative plasticity with the temperature
  // frozen over a step and the mass term make the tangent symmetric positive definite (measured:
  // symmetric to 1e-16); CHOLMOD halves the solve time against UMFPACK at 1800–3300 dofs
  // (bench/studies/friction_laws/README.md) and hands any tangent it finds indefinite to LU.
  numerics::LinearSolverKind linear_solver = numerics::LinearSolverKind::cholesky;
  static NewtonOptions read(OptionKeys& keys);
  bool operator==(const NewtonOptions&) const = default;
};

// The integrator's options from these (its callbacks and end time are the run's to set).
TimeIntegrationOptions integration_options(const TimeOptions& time, const NewtonOptions& newton);

// Heat: adiabatic (seed 000: each point keeps the heat of its plastic work) or conducted through the
// chip (Γ_B held at the load's temperature, the contact face insulated).
enum class ThermalModel { adiabatic, conduction };
struct ThermalOptions {
  ThermalModel model = ThermalModel::conduction;
  double conductivity = 50.0;  // W/(m K), plain carbon steel near room temperature (AISI 1045: ~50)
  bool conducts() const { return model == ThermalModel::conduction; }
  // `model_default`: what an absent thermal.model means (the protocol decides: bench/studies/press_slide_protocol/README.md, the heat study).
  static ThermalOptions read(OptionKeys& keys, ThermalModel model_default);
  bool operator==(const ThermalOptions&) const = default;
};
// The conduction's options for a chip of this material, held at `held_temperature` on Γ_B.
HeatConductionOptions heat_conduction_options(const ThermalOptions& thermal, const JohnsonCookParameters& material,
                                              double held_temperature);

}  // namespace mufric::solid

MUFRIC_OPTION_WORDS(solid::TimeScheme, {"generalized-alpha", solid::TimeScheme::generalized_alpha},
                    {"quasi-static", solid::TimeScheme::quasi_static})
MUFRIC_OPTION_WORDS(solid::VolumetricTreatment, {"full", solid::VolumetricTreatment::full},
                    {"mean-dilatation", solid::VolumetricTreatment::mean_dilatation})
MUFRIC_OPTION_WORDS(solid::ThermalModel, {"adiabatic", solid::ThermalModel::adiabatic},
                    {"conduction", solid::ThermalModel::conduction})
