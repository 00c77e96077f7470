#pragma once
// What a run records at every accepted step (MicroStep), and the averages over μ's window.
#include <optional>
#include <vector>

#include "micro/contact/mortar_contact.hpp"
#include "micro/coupling/lubricated_chip.hpp"
#include "micro/run/chip_model.hpp"
#include "micro/solid/time_integrator.hpp"

namespace mufric::run {

struct MicroStep {
  double time = 0.0;
  double sliding_distance = 0.0;                    // m, of Γ_B since sliding started
  std::optional<double> mu;                         // ∫Tx/∫Ty; none while nothing touches
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  // resultant on the chip (contact + lubricant), N/m
  // Lubricated, once the film has formed: the lubricant's own record of the step (its force on the
  // chip, coupling work, film, pockets, cavities, liquid), as the coupled step wrote it.
  std::optional<coupling::LubricatedStep> lubricant;
  double contact_fraction = 0.0;                    // of the interval's surface length
  // Of the length in contact, the part whose spots the lubricant wets (they take the wetted law; 0 dry).
  double wetted_contact_fraction = 0.0;
  double max_pressure = 0.0;                        // Pa
  int newton_iterations = 0;
  // Since the start, J per unit depth: the energy the interfacial law dissipated at the contact, and
  // the chip's plastic work Σ w σ_y Δε̄ᵖ (0 for the frictionless law / an elastic chip).
  double interface_dissipation = 0.0, plastic_work = 0.0;
  double bottom_rise = 0.0;  // m: Γ_B's mean vertical displacement (toward the tool positive)
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

// What every accepted step records: the contact state, the lubricant's own record of the step, μ by
// eq. (17) over the whole chip boundary (contact and fluid traction), and μ into the window average
// (seed 000 averages over time, press-slide over sliding distance); and the step's interfacial
// dissipation and plastic work per unit sliding distance and normal force into averages over the
// same window (μ's split into its adhesive and ploughing parts).
class StepRecorder {
 public:
  StepRecorder(const Scene& scene, const BottomMotion& motion, const contact::MortarContact& contact,
               const coupling::LubricatedChip* lubricant)
      : seed000_(scene.protocol.name == scene::Protocol::seed000),
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

  const MicroStep& record(const solid::StepView& view);
  std::vector<MicroStep>& history() { return history_; }
  const WindowAverage& average() const { return average_; }
  const WindowAverage& interface_average() const { return interface_average_; }
  const WindowAverage& plastic_average() const { return plastic_average_; }
  const WindowAverage& normal_average() const { return normal_average_; }
  const contact::ContactState& last_contact() const { return last_contact_; }

 private:
  static WindowAverage window(const Scene& scene);
  // Σ_q w_q σ_y Δε̄ᵖ over the step (σ_y, the Kirchhoff yield stress of the return map, at the end of
  // the step: the backward-Euler plastic work of the J2 model).
  double step_plastic_work(const solid::SolidProblem& problem);
  // The mean vertical displacement of Γ_B (the chip's bottom, pushed toward the tool along +y).
  static double bottom_rise(const solid::StepView& view);
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

}  // namespace mufric::run
