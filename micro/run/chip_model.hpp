#pragma once
// The chip model of one micro-model run, set up from its scene: the fitted surfaces with the tool
// placed at the scene's gap, Γ_B's motion under the protocol, the IGA chip under its loads with mortar
// contact and the interface law's point states, heat conduction and the lubricant wired into the time
// integration, and the integrator's options.
#include <memory>
#include <vector>

#include "micro/contact/mortar_contact.hpp"
#include "micro/coupling/lubricated_chip.hpp"
#include "micro/scene/scene.hpp"
#include "micro/solid/heat_conduction.hpp"
#include "micro/solid/time_integrator.hpp"

namespace mufric::run {

using scene::Scene;

// The chip surface and the tool surface as fitted periodic curves, the tool placed above the chip
// at the scene's initial gap.
struct SceneGeometry {
  spline::SplineCurve chip_surface, tool_surface;
};
SceneGeometry build_geometry(const Scene& scene);

// Where Γ_B is and how far it has slid, for the scene's protocol.
class BottomMotion {
 public:
  explicit BottomMotion(const Scene& scene) : velocity_(scene.velocity) {
    if (scene.protocol.name == scene::Protocol::seed000) return;
    const scene::ProtocolSpec& q = scene.protocol;
    const double speed = std::abs(velocity_);
    slide_start_ = scene.ramp + q.press_hold;
    acceleration_time_ = 2.0 * scene::kAccelerationShareOfRunIn * q.run_in / speed;
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

LoadedChip load_chip(const Scene& scene, const SceneGeometry& geometry, const BottomMotion& motion);
// The chip's state at each contact surface point, from the committed state of its nearest bulk
// quadrature point: k = σ_JC(ε̄ᵖ, ε̇ᵖ, T)/√3 (von Mises) and T, for the laws that use them (they see
// the last accepted state's).
void refresh_chip_state_at_contact(const Scene& scene, const LoadedChip& chip);
// The contact points the lubricant wets after the last accepted step (their current positions in
// `contact`, that step's state), for the law's wetted coefficients in the next step — lagged a step
// like k and T. A frictionless law has none: its points report no wetted spot.
void refresh_wetted_contact(const Scene& scene, const LoadedChip& chip, const coupling::LubricatedChip* lubricant,
                            const contact::ContactState& contact);
// The scene's time-integration choices, and the protocol's step lengths.
solid::TimeIntegrationOptions integration_options(const Scene& scene, const BottomMotion& motion);
// Heat conduction through the chip, staggered after every accepted mechanical step (the plastic work
// and the frictional heat raise the quadrature points' temperature; conduction spreads it).
std::unique_ptr<solid::HeatConduction> add_heat_conduction(const Scene& scene, const LoadedChip& chip,
                                                           solid::TimeIntegrationOptions& o);
// The lubricant: its load joins the chip's boundary interactions before the integrator assembles,
// and every step becomes its fluid–structure exchange.
std::unique_ptr<coupling::LubricatedChip> add_lubricant(const Scene& scene, solid::SolidProblem& problem,
                                                        const SceneGeometry& geometry, const BottomMotion& motion,
                                                        solid::TimeIntegrationOptions& o);

}  // namespace mufric::run
