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

long long bit_stable_piece(long long wanted) {
  if (wanted < kEvaluationBlockRows) return std::max(1LL, wanted);
  return wanted - wanted % kEvaluationBlockRows;
}

}  // namespace mufric::wire
