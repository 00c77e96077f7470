#include "proto/wire_codec.hpp"

#include <algorithm>
#include <cmath>


namespace mufric::wire {

// The wire's enums are the model's, value for value: the codec and the server cast between them.
static_assert(static_cast<int>(Extrapolation::raw) == v1::EXTRAPOLATION_RAW);
static_assert(static_cast<int>(Extrapolation::clamp) == v1::EXTRAPOLATION_CLAMP);
static_assert(static_cast<int>(Extrapolation::refuse) == v1::EXTRAPOLATION_REFUSE);
static_assert(static_cast<int>(PointStatus::out_of_box) == v1::POINT_STATUS_OUT_OF_BOX);

const google::protobuf::RepeatedField<double>* input_array(const v1::EvaluateRequest& request, std::string_view name) {
  if (name == input_name::contact_pressure) return &request.contact_pressure();
  if (name == input_name::sliding_velocity) return &request.sliding_velocity();
  if (name == input_name::temperature) return &request.temperature();
  if (name == input_name::fibre_angle) return &request.fibre_angle();
  return nullptr;  // not on the wire (KnownInput::on_the_wire; tested to agree)
}

google::protobuf::RepeatedField<double>* mutable_input_array(v1::EvaluateRequest& request, std::string_view name) {
  // One table of names: a repeated scalar field has no presence bit, so its const accessor's field
  // is the very one mutable_x() returns.
  return const_cast<google::protobuf::RepeatedField<double>*>(input_array(request, name));
}

void encode_options(const EvaluationRequest& what, v1::EvaluateRequest& out) {
  out.set_std(what.std);
  out.set_ci_level(what.ci_level);
  out.set_gradient(what.gradient);
  out.set_patch_std(what.patch_std);
  out.set_extrapolation(static_cast<v1::Extrapolation>(what.extrapolation));
  out.set_mu_tolerance(what.exact_only() ? kExactModelOnly : what.mu_tolerance);
  out.set_std_tolerance(what.exact_only() ? kExactModelOnly : what.std_relative_tolerance);
}

std::string decode_options(const v1::EvaluateRequest& in, EvaluationRequest& what) {
  what = EvaluationRequest{};
  if (in.ci_level() != 0.0 && !(in.ci_level() > 0.0 && in.ci_level() < 1.0)) {
    return "field ci_level must lie in (0, 1) or be 0, got " + std::to_string(in.ci_level());
  }
  what.std = in.std();
  what.ci_level = in.ci_level();
  what.gradient = in.gradient();
  what.patch_std = in.patch_std();
  if (!v1::Extrapolation_IsValid(in.extrapolation())) {
    return "field extrapolation: unknown value " + std::to_string(static_cast<int>(in.extrapolation()));
  }
  what.extrapolation = static_cast<Extrapolation>(in.extrapolation());
  if (!std::isfinite(in.mu_tolerance()) || !std::isfinite(in.std_tolerance())) {
    return "fields mu_tolerance and std_tolerance must be finite";
  }
  if (in.mu_tolerance() < 0.0 || in.std_tolerance() < 0.0) {
    what.mu_tolerance = what.std_relative_tolerance = 0.0;
  } else {
    if (in.mu_tolerance() > 0.0) what.mu_tolerance = in.mu_tolerance();
    if (in.std_tolerance() > 0.0) what.std_relative_tolerance = in.std_tolerance();
  }
  return {};
}

void encode_description(const FrictionModel& model, const std::string& name, const std::string& version,
                        v1::ModelDescription& out) {
  out.set_name(name);
  out.set_version(version);
  out.set_kind(std::string(model.kind()));
  for (const auto& input : model.inputs()) {
    auto* d = out.add_inputs();
    d->set_name(input.name);
    d->set_unit(input.unit);
    d->set_lo(input.lo);
    d->set_hi(input.hi);
  }
  out.set_has_uncertainty(model.has_uncertainty());
  out.set_extrapolation(static_cast<v1::Extrapolation>(model.default_extrapolation()));
  out.set_mu_min(model.mu_min());
  out.set_mu_max(model.mu_max());
  const KindDescription kind = model.kind_description();
  if (const auto& training = kind.training) {
    out.set_training_points(static_cast<uint64_t>(training->training_points));
    out.set_loo_mean_relative_error(training->loo_mean_relative_error);
    out.set_loo_max_relative_error(training->loo_max_relative_error);
    out.set_loo_coverage_95(training->loo_coverage_95);
    out.set_interval_meaning(training->interval_meaning);
    out.set_interval(training->interval);
    out.set_micro_std_error(training->micro_std_error);
  }
  if (const auto& calibration = kind.calibration) {
    auto* c = out.mutable_calibration();
    c->set_data_source(calibration->data_source);
    c->set_measurements(static_cast<uint64_t>(calibration->measurements));
    c->set_discrepancy(calibration->discrepancy);
    c->set_posterior_samples(static_cast<uint64_t>(calibration->posterior_samples));
    for (const auto& p : calibration->parameters) {
      auto* q = c->add_parameters();
      q->set_name(p.name);
      q->set_mean(p.mean);
      q->set_sd(p.sd);
      q->set_lo95(p.lo95);
      q->set_hi95(p.hi95);
    }
    auto* parts = c->mutable_at_box_centre();
    parts->set_mu(calibration->at_box_centre.mu);
    parts->set_sd(calibration->at_box_centre.sd);
    parts->set_parameter_sd(calibration->at_box_centre.parameter_sd);
    parts->set_conditional_sd(calibration->at_box_centre.conditional_sd);
    parts->set_emulator_sd(calibration->at_box_centre.emulator_sd);
    parts->set_discrepancy_sd(calibration->at_box_centre.discrepancy_sd);
  }
  out.set_has_patch_scatter(model.has_patch_scatter());
  out.set_summary(model.summary());
}

InputSpace decode_inputs(const v1::ModelDescription& in) {
  InputSpace inputs;
  for (const auto& input : in.inputs()) inputs.push_back({input.name(), input.unit(), input.lo(), input.hi()});
  return inputs;
}

std::optional<Extrapolation> decode_extrapolation(const v1::ModelDescription& in) {
  if (in.extrapolation() == v1::EXTRAPOLATION_MODEL_DEFAULT || !v1::Extrapolation_IsValid(in.extrapolation())) {
    return std::nullopt;
  }
  return static_cast<Extrapolation>(in.extrapolation());
}

std::optional<CalibrationDescription> decode_calibration(const v1::ModelDescription& in) {
  if (!in.has_calibration()) return std::nullopt;
  const auto& c = in.calibration();
  CalibrationDescription calibration;
  calibration.data_source = c.data_source();
  calibration.measurements = static_cast<long long>(c.measurements());
  calibration.posterior_samples = static_cast<long long>(c.posterior_samples());
  calibration.discrepancy = c.discrepancy();
  for (const auto& p : c.parameters()) calibration.parameters.push_back({p.name(), p.mean(), p.sd(), p.lo95(), p.hi95()});
  const auto& parts = c.at_box_centre();
  calibration.at_box_centre = {parts.mu(), parts.sd(), parts.parameter_sd(), parts.conditional_sd(), parts.emulator_sd(),
                               parts.discrepancy_sd()};
  return calibration;
}

void reserve_answers(const EvaluationRequest& what, bool patch_std, int n, const InputSpace& inputs,
                     v1::EvaluateResponse& out) {
  out.mutable_mu()->Reserve(n);
  if (what.std) out.mutable_std()->Reserve(n);
  if (what.ci_level > 0.0) {
    out.mutable_lo()->Reserve(n);
    out.mutable_hi()->Reserve(n);
  }
  if (what.gradient) {
    out.mutable_gradient()->Reserve(n * static_cast<int>(inputs.size()));
    for (const auto& input : inputs) out.add_gradient_inputs(input.name);
  }
  if (patch_std) out.mutable_patch_std()->Reserve(n);
  out.mutable_status()->Reserve(n);
}

void append_answers(const Evaluation& e, const EvaluationRequest& what, bool patch_std, v1::EvaluateResponse& out) {
  const auto count = static_cast<Eigen::Index>(e.status.size());
  out.mutable_mu()->Add(e.mu.data(), e.mu.data() + count);
  if (what.std) out.mutable_std()->Add(e.std.data(), e.std.data() + count);
  if (what.ci_level > 0.0) {
    out.mutable_lo()->Add(e.lo.data(), e.lo.data() + count);
    out.mutable_hi()->Add(e.hi.data(), e.hi.data() + count);
  }
  if (what.gradient) {
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = e.gradient;
    out.mutable_gradient()->Add(rows.data(), rows.data() + rows.size());
  }
  if (patch_std) out.mutable_patch_std()->Add(e.patch_std.data(), e.patch_std.data() + count);
  for (const PointStatus s : e.status) out.mutable_status()->Add(static_cast<int>(s));
}

long long bit_stable_piece(long long wanted) {
  if (wanted < kEvaluationBlockRows) return std::max(1LL, wanted);
  return wanted - wanted % kEvaluationBlockRows;
}

}  // namespace mufric::wire
