#include "micro/run/step_recorder.hpp"

#include <cmath>
#include <limits>

#include "micro/solid/materials.hpp"

namespace mufric::run {
using namespace scene;

const MicroStep& StepRecorder::record(const solid::StepView& view) {
  last_contact_ = contact_.state(view.u);
  MicroStep step;
  step.time = view.time;
  step.sliding_distance = motion_.distance(view.time);
  step.force = last_contact_.force;
  if (lubricant_ && !lubricant_->history().empty()) {
    step.lubricant = lubricant_->history().back();
    step.force += step.lubricant->fluid_force;
  }
  if (step.force.y() != 0.0) step.mu = step.force.x() / step.force.y();  // eq. (17)
  step.contact_fraction = last_contact_.contact_length / last_contact_.surface_length;
  if (last_contact_.contact_length > 0.0) {
    step.wetted_contact_fraction = last_contact_.wetted_contact_length / last_contact_.contact_length;
  }
  step.max_pressure = last_contact_.max_pressure;
  step.interface_dissipation = contact_.dissipated_energy();
  step.plastic_work = plastic_work_ += step_plastic_work(view.problem);
  step.bottom_rise = bottom_rise(view);
  if (step.mu) average_.add(position(previous_time_), position(view.time), *step.mu);
  const double slid = step.sliding_distance - motion_.distance(previous_time_);
  if (slid > 0.0 && step.force.y() != 0.0) {
    const double per_slid_load = 1.0 / (slid * std::abs(step.force.y()));
    const double previous_dissipation = history_.empty() ? 0.0 : history_.back().interface_dissipation;
    interface_average_.add(position(previous_time_), position(view.time),
                           (step.interface_dissipation - previous_dissipation) * per_slid_load);
    const double previous_work = history_.empty() ? 0.0 : history_.back().plastic_work;
    plastic_average_.add(position(previous_time_), position(view.time), (step.plastic_work - previous_work) * per_slid_load);
    const double previous_rise = history_.empty() ? 0.0 : history_.back().bottom_rise;
    normal_average_.add(position(previous_time_), position(view.time), (step.bottom_rise - previous_rise) / slid);
  }
  previous_time_ = view.time;
  history_.push_back(std::move(step));
  return history_.back();
}

WindowAverage StepRecorder::window(const Scene& scene) {
  if (scene.protocol.name == Protocol::seed000) {
    return WindowAverage(scene.average_from, std::numeric_limits<double>::infinity(), 0);
  }
  return WindowAverage(scene.protocol.run_in, scene.protocol.run_in + scene.protocol.window, scene.protocol.blocks);
}

double StepRecorder::step_plastic_work(const solid::SolidProblem& problem) {
  const auto& states = problem.states();
  const auto& qps = problem.space().quadrature();
  if (plastic_strain_.empty()) plastic_strain_.assign(states.size(), 0.0);
  double work = 0.0;
  for (size_t q = 0; q < states.size(); ++q) {
    const auto& st = states[q];
    const double increment = st.equivalent_plastic_strain - plastic_strain_[q];
    if (increment <= 0.0) continue;
    work += qps[q].weight * increment *
            solid::johnson_cook_yield_stress(material_, st.equivalent_plastic_strain, st.plastic_strain_rate, st.temperature);
    plastic_strain_[q] = st.equivalent_plastic_strain;
  }
  return work;
}

double StepRecorder::bottom_rise(const solid::StepView& view) {
  const std::vector<int> nodes = view.problem.space().side_nodes(numerics::Side::bottom);
  double sum = 0.0;
  for (const int a : nodes) sum += view.u(2 * a + 1);
  return nodes.empty() ? 0.0 : sum / static_cast<double>(nodes.size());
}

}  // namespace mufric::run
