#include "server/friction_service.hpp"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdio>
#include <exception>
#include <string_view>

#include <grpcpp/alarm.h>
#include <omp.h>

#include "common/units.hpp"
#include "common/version.hpp"
#include "proto/wire_codec.hpp"

namespace mufric::server {
namespace {

using mufric::v1::EvaluateRequest;

using wire::input_array;

void add_model_summaries(const ModelRegistry& registry,
                         google::protobuf::RepeatedPtrField<mufric::v1::ModelSummary>& summaries) {
  for (const auto& served : registry.all()) {
    auto* m = summaries.Add();
    m->set_name(served->name);
    m->set_version(served->version);
    m->set_kind(std::string(served->model->kind()));
  }
}

// OK while the caller still waits for the answer; otherwise why not, with how far evaluation got.
grpc::Status caller_gone(const grpc::CallbackServerContext& context, int done, int total) {
  const std::string progress = " after " + std::to_string(done) + " of " + std::to_string(total) + " points";
  if (context.IsCancelled()) return {grpc::StatusCode::CANCELLED, "the caller cancelled the call" + progress};
  if (std::chrono::system_clock::now() > context.deadline()) {
    return {grpc::StatusCode::DEADLINE_EXCEEDED, "the call's deadline passed" + progress};
  }
  return grpc::Status::OK;
}

// A refusal the client should retry: RESOURCE_EXHAUSTED with the hint wire::kRetryAfterKey, which
// mufric's clients follow (a RESOURCE_EXHAUSTED without it, too many points, is not retried).
grpc::Status retry_later(grpc::CallbackServerContext& context, std::string message) {
  context.AddTrailingMetadata(wire::kRetryAfterKey, std::to_string(kRetryAfterMs));
  return {grpc::StatusCode::RESOURCE_EXHAUSTED, std::move(message)};
}

}  // namespace

grpc::Status batch_from_request(const EvaluateRequest& request, const InputSpace& inputs, long long max_points,
                                QueryBatch& batch, std::vector<std::string>& ignored) {
  long long points = -1;
  std::string first_name;
  for (const auto& input : inputs) {
    const auto* array = input_array(request, input.name);
    if (array == nullptr) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              "the model needs input '" + input.name + "', which the wire contract does not carry"};
    }
    if (array->empty()) {
      return {grpc::StatusCode::INVALID_ARGUMENT, "field " + input.name + " is empty; the model '" + request.model() +
                                                      "' needs it (one value per point)"};
    }
    if (points < 0) {
      points = array->size();
      first_name = input.name;
    } else if (array->size() != points) {
      return {grpc::StatusCode::INVALID_ARGUMENT, "field " + input.name + " has " + std::to_string(array->size()) +
                                                      " values but " + first_name + " has " + std::to_string(points)};
    }
  }
  if (points > max_points) {
    return {grpc::StatusCode::RESOURCE_EXHAUSTED, std::to_string(points) + " points exceed the server's limit of " +
                                                      std::to_string(max_points) + " per request (--max-points); split the block"};
  }
  batch.resize(points, static_cast<Eigen::Index>(inputs.size()));
  for (size_t j = 0; j < inputs.size(); ++j) {
    const auto* array = input_array(request, inputs[j].name);
    batch.col(static_cast<Eigen::Index>(j)) = Eigen::Map<const Eigen::VectorXd>(array->data(), points);
  }
  for (const std::string& name : known_input_names()) {
    const bool used = std::any_of(inputs.begin(), inputs.end(), [&](const InputSpec& s) { return s.name == name; });
    const auto* array = input_array(request, name);
    if (!used && array != nullptr && !array->empty()) ignored.emplace_back(name);
  }
  return grpc::Status::OK;
}

void describe(const ServedModel& served, mufric::v1::ModelDescription& out) {
  wire::encode_description(*served.model, served.name, served.version, out);
}

std::size_t evaluation_bytes(const EvaluateRequest& request, int gradient_width, bool patch_std) {
  std::size_t points = 0;
  for (const std::string& name : known_input_names()) {
    if (const auto* array = input_array(request, name)) points = std::max(points, static_cast<std::size_t>(array->size()));
  }
  const auto width = static_cast<std::size_t>(std::max(gradient_width, 1));
  const std::size_t answer_doubles = 1 + (request.std() ? 1 : 0) + (request.ci_level() > 0.0 ? 2 : 0) +
                                     (patch_std ? 1 : 0) + (request.gradient() ? width : 0);
  const std::size_t answer_bytes = points * (answer_doubles * sizeof(double) + 1);  // + the status byte
  return request.ByteSizeLong() + points * width * sizeof(double) + 2 * answer_bytes;
}

int threads_per_evaluation(int evaluation_threads, int in_flight) {
  return std::max(1, evaluation_threads / std::max(1, in_flight));
}

grpc::Status FrictionService::evaluate(const EvaluateRequest& request, mufric::v1::EvaluateResponse& response,
                                       const CallerCheck& gone_check) {
  const auto served = registry_.find(request.model());
  if (!served) {
    return {grpc::StatusCode::NOT_FOUND, "model '" + request.model() + "' is not served; serving: " + registry_.names()};
  }
  if (!request.version().empty() && request.version() != served->version) {
    return {grpc::StatusCode::NOT_FOUND, "model '" + request.model() + "' version " + request.version() +
                                             " is not served; the current version is " + served->version};
  }
  EvaluationRequest what;
  if (const std::string why = wire::decode_options(request, what); !why.empty()) {
    return {grpc::StatusCode::INVALID_ARGUMENT, why};
  }
  const FrictionModel& model = *served->model;
  QueryBatch batch;
  std::vector<std::string> ignored;
  grpc::Status status = batch_from_request(request, model.inputs(), limits_.max_points_per_request, batch, ignored);
  if (!status.ok()) return status;
  const auto n = static_cast<int>(batch.rows());
  response.set_model(served->name);
  response.set_version(served->version);
  const bool patch = what.patch_std && model.has_patch_scatter();
  UncertainQueryLog* const log = model.has_uncertainty() ? limits_.uncertain_log : nullptr;
  EvaluationRequest computed = what;
  computed.std = what.std || log != nullptr;
  wire::reserve_answers(what, patch, n, model.inputs(), response);
  uint64_t extrapolated = 0, invalid = 0, fast = 0, out_of_box = 0, clipped = 0;
  // Chunks, so that a call whose caller has given up (deadline passed, cancelled) stops within a
  // few milliseconds instead of computing an answer nobody reads.
  const int piece = static_cast<int>(wire::bit_stable_piece(kPointsBetweenDeadlineChecks));
  for (int first = 0; first < n; first += piece) {
    if (grpc::Status gone = gone_check ? gone_check(first, n) : grpc::Status::OK; !gone.ok()) {
      ++counters_.abandoned;
      return gone;
    }
    const int count = std::min(n - first, piece);
    const Evaluation e = count == n ? model.evaluate(batch, computed)
                                    : model.evaluate(QueryBatch(batch.middleRows(first, count)), computed);
    if (log != nullptr) log->record(served->name, model.inputs(), batch.middleRows(first, count), e.std);
    fast += static_cast<uint64_t>(e.fast_points);
    clipped += static_cast<uint64_t>(e.range_clipped);
    wire::append_answers(e, what, patch, response);
    for (const PointStatus s : e.status) {
      extrapolated += s == PointStatus::extrapolated;
      invalid += s == PointStatus::invalid_input;
      out_of_box += s == PointStatus::out_of_box;
    }
  }
  response.set_extrapolated_points(extrapolated);
  response.set_invalid_points(invalid);
  response.set_fast_points(fast);
  response.set_out_of_box_points(out_of_box);
  response.set_range_clipped_points(clipped);
  if (invalid + out_of_box + extrapolated > 0) {
    std::vector<PointStatus> all(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) all[static_cast<size_t>(i)] = static_cast<PointStatus>(response.status(i));
    response.set_message(block_message(model.inputs(), batch, all,
                                       effective_extrapolation(what.extrapolation, model.default_extrapolation())));
  }
  counters_.fast_points += static_cast<long long>(fast);
  for (auto& name : ignored) response.add_ignored_inputs(std::move(name));
  counters_.points += n;
  return grpc::Status::OK;
}

grpc::Status FrictionService::authorise(const grpc::CallbackServerContext& context) const {
  if (limits_.bearer_token.empty()) return grpc::Status::OK;
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  if (it != metadata.end()) {
    // "Bearer <token>": the scheme is case-insensitive (RFC 7235 §2.1), the token is not.
    const std::string_view value(it->second.data(), it->second.size());
    constexpr std::string_view kScheme = "bearer ";
    const bool scheme_matches = value.size() >= kScheme.size() &&
                                std::equal(kScheme.begin(), kScheme.end(), value.begin(), [](char a, char b) {
                                  return a == std::tolower(static_cast<unsigned char>(b));
                                });
    if (scheme_matches && value.substr(kScheme.size()) == limits_.bearer_token) return grpc::Status::OK;
  }
  return {grpc::StatusCode::UNAUTHENTICATED, "missing or wrong bearer token (metadata 'authorization: Bearer ...')"};
}

grpc::ServerUnaryReactor* FrictionService::refuse_unless_authorised(grpc::CallbackServerContext* context) {
  grpc::Status status = authorise(*context);
  if (status.ok()) return nullptr;
  ++counters_.errors;
  auto* reactor = context->DefaultReactor();
  reactor->Finish(status);
  return reactor;
}

grpc::Status FrictionService::admit(grpc::CallbackServerContext& context, const EvaluateRequest& request,
                                    MemoryBudget::Reservation& held) {
  const auto served = registry_.find(request.model());
  const int width = served ? static_cast<int>(served->model->inputs().size()) : static_cast<int>(known_input_names().size());
  const std::size_t bytes = evaluation_bytes(request, width, request.patch_std());
  held = memory_.try_reserve(bytes);
  if (held) return grpc::Status::OK;
  ++counters_.refused_busy;
  constexpr double kMB = 1024.0 * 1024.0;
  char text[256];
  std::snprintf(text, sizeof text,
                "the server is busy: this call needs %.1f MB and %.1f MB of its %.0f MB for calls in flight are "
                "taken (serve --max-memory-mb); retry after %d ms",
                static_cast<double>(bytes) / kMB, static_cast<double>(memory_.in_use()) / kMB,
                static_cast<double>(memory_.limit()) / kMB, kRetryAfterMs);
  return retry_later(context, text);
}

grpc::Status FrictionService::handle(grpc::CallbackServerContext& context, const EvaluateRequest& request,
                                     mufric::v1::EvaluateResponse& response, MemoryBudget::Reservation& held) {
  const auto start = std::chrono::steady_clock::now();
  // The OpenMP thread count is per calling thread, and gRPC runs handlers on its own threads.
  omp_set_num_threads(threads_per_evaluation(limits_.evaluation_threads, counters_.in_flight.load()));
  grpc::Status status = admit(context, request, held);
  try {
    if (status.ok()) {
      status = evaluate(request, response, [&context](int done, int total) { return caller_gone(context, done, total); });
    }
  } catch (const std::exception& e) {
    status = grpc::Status(grpc::StatusCode::INTERNAL, std::string("evaluation failed: ") + e.what());
  }
  if (!status.ok()) ++counters_.errors;
  const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  const auto bucket = std::lower_bound(kLatencyBoundsUs.begin(), kLatencyBoundsUs.end(), us) - kLatencyBoundsUs.begin();
  ++counters_.latency[static_cast<size_t>(bucket)];
  return status;
}

// Holds the call's memory reservation until gRPC has sent the answer (OnDone).
class FrictionService::UnaryReactor final : public grpc::ServerUnaryReactor {
 public:
  MemoryBudget::Reservation held;
  void OnDone() override { delete this; }
};

grpc::ServerUnaryReactor* FrictionService::Evaluate(grpc::CallbackServerContext* context, const EvaluateRequest* request,
                                                    mufric::v1::EvaluateResponse* response) {
  ++counters_.in_flight;
  ++counters_.requests;  // answered or refused, each is a request (and a refusal an error too)
  auto* reactor = new UnaryReactor;
  grpc::Status status = authorise(*context);
  if (status.ok()) {
    status = handle(*context, *request, *response, reactor->held);
  } else {
    ++counters_.errors;
  }
  reactor->Finish(status);
  --counters_.in_flight;
  return reactor;
}

// Read a block, answer it, read the next: one response per request, in order. An answer the client
// does not take within stream_write_seconds cancels the stream; its memory reservation is held from
// the request until the answer is written.
class FrictionService::StreamReactor final
    : public grpc::ServerBidiReactor<EvaluateRequest, mufric::v1::EvaluateResponse> {
 public:
  StreamReactor(FrictionService& service, grpc::CallbackServerContext& context, const grpc::Status& admitted)
      : service_(service), context_(context), watch_(std::make_shared<WriteWatch>()) {
    ++service_.counters_.streams;
    ++service_.counters_.open_streams;
    watch_->context = &context;
    if (admitted.ok()) {
      StartRead(&request_);
    } else {
      ++service_.counters_.requests;
      ++service_.counters_.errors;
      Finish(admitted);
    }
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client closed its side: done
      Finish(grpc::Status::OK);
      return;
    }
    ++service_.counters_.in_flight;
    ++service_.counters_.requests;
    response_.Clear();
    const grpc::Status status = service_.handle(context_, request_, response_, held_);
    if (status.ok()) {
      watch_write();
      StartWrite(&response_);
    } else {
      held_.release();
      --service_.counters_.in_flight;
      Finish(status);
    }
  }

  void OnWriteDone(bool ok) override {
    {
      std::lock_guard lock(watch_->mutex);
      ++watch_->writes_done;
    }
    held_.release();
    --service_.counters_.in_flight;
    if (!ok) {
      Finish(grpc::Status(grpc::StatusCode::CANCELLED, "the client went away"));
      return;
    }
    StartRead(&request_);
  }

  void OnDone() override {
    {
      std::lock_guard lock(watch_->mutex);
      watch_->context = nullptr;  // an alarm firing from now on finds nothing to cancel
    }
    --service_.counters_.open_streams;
    delete this;
  }

 private:
  // Shared with the write alarms, which may fire after the reactor is gone (grpc::Alarm does not
  // wait for its callback on Cancel or destruction).
  struct WriteWatch {
    std::mutex mutex;
    grpc::CallbackServerContext* context = nullptr;
    long long writes_done = 0;
  };

  void watch_write() {
    if (service_.limits_.stream_write_seconds <= 0.0) return;
    long long write;
    {
      std::lock_guard lock(watch_->mutex);
      write = watch_->writes_done;
    }
    const auto deadline = std::chrono::system_clock::now() +
                          std::chrono::duration_cast<std::chrono::system_clock::duration>(
                              std::chrono::duration<double>(service_.limits_.stream_write_seconds));
    alarm_ = std::make_unique<grpc::Alarm>();  // the previous one, cancelled, fires with ok = false
    alarm_->Set(deadline, [watch = watch_, write, stalled = &service_.counters_.stalled_streams](bool fired) {
      if (!fired) return;
      std::lock_guard lock(watch->mutex);
      if (watch->context == nullptr || watch->writes_done != write) return;  // gone, or the answer was taken
      ++*stalled;
      watch->context->TryCancel();
    });
  }

  FrictionService& service_;
  grpc::CallbackServerContext& context_;
  EvaluateRequest request_;
  mufric::v1::EvaluateResponse response_;
  MemoryBudget::Reservation held_;
  std::shared_ptr<WriteWatch> watch_;
  std::unique_ptr<grpc::Alarm> alarm_;
};

grpc::ServerBidiReactor<EvaluateRequest, mufric::v1::EvaluateResponse>* FrictionService::EvaluateStream(
    grpc::CallbackServerContext* context) {
  grpc::Status admitted = authorise(*context);
  if (admitted.ok() && limits_.max_streams > 0 && counters_.open_streams.load() >= limits_.max_streams) {
    ++counters_.refused_streams;
    admitted = retry_later(*context, std::to_string(limits_.max_streams) +
                                         " streams are open, the server's limit (serve --max-streams); retry after " +
                                         std::to_string(kRetryAfterMs) + " ms, or send blocks over fewer streams");
  }
  return new StreamReactor(*this, *context, admitted);
}

grpc::ServerUnaryReactor* FrictionService::ListModels(grpc::CallbackServerContext* context,
                                                      const mufric::v1::ListModelsRequest*,
                                                      mufric::v1::ListModelsResponse* response) {
  ++counters_.requests;
  if (auto* refusal = refuse_unless_authorised(context)) return refusal;
  auto* reactor = context->DefaultReactor();
  add_model_summaries(registry_, *response->mutable_models());
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* FrictionService::GetServerStatus(grpc::CallbackServerContext* context,
                                                           const mufric::v1::ServerStatusRequest*,
                                                           mufric::v1::ServerStatus* response) {
  if (auto* refusal = refuse_unless_authorised(context)) return refusal;
  auto* reactor = context->DefaultReactor();
  response->set_code_version(code_version());
  response->set_uptime_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count());
  response->set_requests(static_cast<uint64_t>(counters_.requests.load()));
  response->set_points(static_cast<uint64_t>(counters_.points.load()));
  response->set_errors(static_cast<uint64_t>(counters_.errors.load()));
  response->set_in_flight(static_cast<uint64_t>(counters_.in_flight.load()));
  response->set_abandoned(static_cast<uint64_t>(counters_.abandoned.load()));
  response->set_streams(static_cast<uint64_t>(counters_.streams.load()));
  response->set_fast_points(static_cast<uint64_t>(counters_.fast_points.load()));
  response->set_memory_limit_bytes(memory_.limit());
  response->set_memory_in_use_bytes(memory_.in_use());
  response->set_refused_busy(static_cast<uint64_t>(counters_.refused_busy.load()));
  response->set_open_streams(static_cast<uint64_t>(std::max(0, counters_.open_streams.load())));
  response->set_refused_streams(static_cast<uint64_t>(counters_.refused_streams.load()));
  response->set_stalled_streams(static_cast<uint64_t>(counters_.stalled_streams.load()));
  response->set_evaluation_threads(static_cast<uint32_t>(limits_.evaluation_threads));
  for (const double bound : kLatencyBoundsUs) response->add_latency_bounds_us(bound);
  for (const auto& count : counters_.latency) response->add_latency_counts(static_cast<uint64_t>(count.load()));
  add_model_summaries(registry_, *response->mutable_models());
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* FrictionService::DescribeModel(grpc::CallbackServerContext* context,
                                                         const mufric::v1::DescribeModelRequest* request,
                                                         mufric::v1::ModelDescription* response) {
  ++counters_.requests;
  if (auto* refusal = refuse_unless_authorised(context)) return refusal;
  auto* reactor = context->DefaultReactor();
  const auto served = registry_.find(request->model());
  if (!served) {
    ++counters_.errors;
    reactor->Finish({grpc::StatusCode::NOT_FOUND, "model '" + request->model() + "' is not served; serving: " + registry_.names()});
    return reactor;
  }
  describe(*served, *response);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

}  // namespace mufric::server
