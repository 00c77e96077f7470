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
// The contact points' state beyond their pressure, which the provider reads itself from the chip
// (the material computes k at the bulk quadrature point nearest each surface point; T there) and from
// the lubricant (whether it wets the point at its position in the contact's last commit), for what
// the law needs. Read at step boundaries (latch: at load and after every accepted step, once its heat
// and record are done), so that every evaluation within a step — its Newton iterations, the
// contact's commit and the step's record — sees the state it started from: lagged one step, which
// keeps ∂k/∂u out of the tangent and the recorded shear the one the step solved for.
class ChipPointStates final : public contact::PointStateProvider {
 public:
  ChipPointStates(const solid::SolidProblem& problem, std::vector<size_t> surface_quadrature, double sliding_velocity,
                  contact::PointStateNeeds needs);
  contact::ContactPointState state(size_t point) const override;
  std::optional<std::string> missing(const contact::PointStateNeeds& needs) const override;
  // The lubricant, and the contact at whose committed positions it wets points (a lubricated run's).
  void attach_lubricant(const coupling::LubricatedChip* lubricant, const contact::MortarContact* contact);
  // Reads the chip's committed state and the lubricant's wetted spots for the next step.
  void latch();

 private:
  const solid::SolidProblem& problem_;
  std::vector<size_t> surface_quadrature_;  // the bulk quadrature point nearest each surface point
  double sliding_velocity_;
  contact::PointStateNeeds needs_;
  const coupling::LubricatedChip* lubricant_ = nullptr;
  const contact::MortarContact* contact_ = nullptr;
  std::vector<contact::ContactPointState> latched_;
};

struct LoadedChip {
  std::unique_ptr<solid::SolidProblem> problem;
  std::shared_ptr<contact::MortarContact> contact;
  std::shared_ptr<ChipPointStates> point_states;
};

LoadedChip load_chip(const Scene& scene, const SceneGeometry& geometry, const BottomMotion& motion);
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
