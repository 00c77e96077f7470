#pragma once
// The one translation between the in-process evaluation types (surrogate/core/friction_model.hpp) and the
// wire (proto/mufric/v1/friction.proto), shared by the C++ client and the server: which request
// array carries which model input, what to compute with which tolerances, and the replies (a model's
// description, an evaluation's answers). Each side used to spell these itself, and "use the exact
// model" had three encodings.
#include <optional>
#include <string>
#include <string_view>

#include "mufric/v1/friction.pb.h"
#include "surrogate/core/friction_model.hpp"

namespace mufric::wire {

// The request's array that carries a named model input (common/units.hpp known_input_names());
// nullptr for a name the wire does not carry.
const google::protobuf::RepeatedField<double>* input_array(const v1::EvaluateRequest& request, std::string_view name);
google::protobuf::RepeatedField<double>* mutable_input_array(v1::EvaluateRequest& request, std::string_view name);

// On the wire a negative tolerance asks for the exact model only (EvaluationRequest: either
// tolerance 0), and 0 (a field a client did not set) leaves the server's default.
inline constexpr double kExactModelOnly = -1.0;

// Trailing metadata of a call refused with RESOURCE_EXHAUSTED because the server's memory for calls
// in flight (or its streams) were taken: milliseconds after which a retry is likely admitted. A
// RESOURCE_EXHAUSTED without it (too many points in one request) is not worth retrying.
inline constexpr const char* kRetryAfterKey = "mufric-retry-after-ms";
// gRPC's words for a call its transport shed under memory pressure (the server's ResourceQuota),
// retried like a refusal with the hint kTransportShedRetryMs.
inline constexpr const char* kTransportShedMessage = "RST_STREAM with error code 11";
inline constexpr double kTransportShedRetryMs = 50.0;

// What to compute (std, interval, gradient, patch scatter), the tolerances and the extrapolation
// policy, onto the wire.
void encode_options(const EvaluationRequest& what, v1::EvaluateRequest& out);
// The wire's options as an EvaluationRequest (its defaults where the wire leaves them); "" or the
// reason a request is invalid, naming the field.
std::string decode_options(const v1::EvaluateRequest& in, EvaluationRequest& what);

// DescribeModel's reply: a served model (its name and version as the registry serves them) onto
// the wire, and back the parts a client keeps (its inputs with their box, its own policy outside the
// box, a calibrated model's calibration).
void encode_description(const FrictionModel& model, const std::string& name, const std::string& version,
                        v1::ModelDescription& out);
InputSpace decode_inputs(const v1::ModelDescription& in);
// The model's own policy outside its box; nullopt when the reply leaves it unsaid (an older server).
std::optional<Extrapolation> decode_extrapolation(const v1::ModelDescription& in);
std::optional<CalibrationDescription> decode_calibration(const v1::ModelDescription& in);

// An Evaluate reply's answers: room for n points of what `what` asks (the gradient's inputs named),
// then each piece of an evaluation appended in order (the gradient row-major, one row per point).
void reserve_answers(const EvaluationRequest& what, bool patch_std, int n, const InputSpace& inputs,
                     v1::EvaluateResponse& out);
void append_answers(const Evaluation& e, const EvaluationRequest& what, bool patch_std, v1::EvaluateResponse& out);

// Points per piece when a batch is cut into pieces (the client's calls, the server's looks at the
// deadline): `wanted` (at least 1), cut down to a multiple of the models' evaluation block when it is at
// least one block, so that a point's σ keeps its bits however a batch is cut (kEvaluationBlockRows).
long long bit_stable_piece(long long wanted);

}  // namespace mufric::wire
