#pragma once
// The gRPC FrictionService (callback API) over a ModelRegistry.
#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "mufric/v1/friction.grpc.pb.h"
#include "server/memory_budget.hpp"
#include "server/model_registry.hpp"
#include "common/uncertain_log.hpp"

namespace mufric::server {

struct ServiceLimits {
  long long max_points_per_request = 1'000'000;
  // When set, every FrictionService call must carry "authorization: Bearer <token>" or gets
  // UNAUTHENTICATED. Health and reflection stay open for probes.
  std::string bearer_token;
  // Cores one batch may use when it is the only evaluation running (`--threads`). With k
  // evaluations in flight each gets max(1, threads / k), so concurrent clients do not oversubscribe
  // the machine with nested thread teams.
  int evaluation_threads = 1;
  // When set, points with a wide interval are logged there (computing std for every call).
  UncertainQueryLog* uncertain_log = nullptr;
  // Bytes the calls in flight may hold (request_memory_bytes: their requests, answers and the
  // answers' wire copies); 0: no limit. A call that does not fit is refused with RESOURCE_EXHAUSTED
  // and the metadata wire::kRetryAfterKey (the clients retry it).
  std::size_t request_memory_bytes = 0;
  // EvaluateStream calls open at once; more are refused with RESOURCE_EXHAUSTED. 0: no limit.
  int max_streams = 0;
  // A stream whose answer the client has not taken within this long is cancelled (its answer held
  // memory for a reader that may never come). 0: no limit.
  double stream_write_seconds = 0.0;
};

// The retry hint (wire::kRetryAfterKey) of a call refused for want of memory or streams.
inline constexpr int kRetryAfterMs = 50;

// What one Evaluate holds at its peak: the request, its points copied into a batch, and the answer
// twice (the response message and its serialised copy). gradient_width: the model's input count.
std::size_t evaluation_bytes(const mufric::v1::EvaluateRequest& request, int gradient_width, bool patch_std);

// Points evaluated between two looks at the caller's deadline and cancellation: a few ms of work
// (cut to wire::bit_stable_piece).
inline constexpr long long kPointsBetweenDeadlineChecks = 8192;

// Threads for one evaluation when `in_flight` evaluations (this one included) are running.
int threads_per_evaluation(int evaluation_threads, int in_flight);

// Copies the request's packed arrays into a batch in the model's input order. Unequal lengths or a
// missing input give INVALID_ARGUMENT naming the field; inputs the model does not use are listed.
grpc::Status batch_from_request(const mufric::v1::EvaluateRequest& request, const InputSpace& inputs,
                                long long max_points, QueryBatch& batch, std::vector<std::string>& ignored);

void describe(const ServedModel& served, mufric::v1::ModelDescription& out);

class FrictionService final : public mufric::v1::FrictionService::CallbackService {
 public:
  FrictionService(const ModelRegistry& registry, ServiceLimits limits)
      : registry_(registry), limits_(limits), memory_(limits.request_memory_bytes) {}

  grpc::ServerUnaryReactor* Evaluate(grpc::CallbackServerContext* context, const mufric::v1::EvaluateRequest* request,
                                     mufric::v1::EvaluateResponse* response) override;
  grpc::ServerBidiReactor<mufric::v1::EvaluateRequest, mufric::v1::EvaluateResponse>* EvaluateStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* ListModels(grpc::CallbackServerContext* context, const mufric::v1::ListModelsRequest* request,
                                       mufric::v1::ListModelsResponse* response) override;
  grpc::ServerUnaryReactor* GetServerStatus(grpc::CallbackServerContext* context,
                                            const mufric::v1::ServerStatusRequest* request,
                                            mufric::v1::ServerStatus* response) override;
  grpc::ServerUnaryReactor* DescribeModel(grpc::CallbackServerContext* context,
                                          const mufric::v1::DescribeModelRequest* request,
                                          mufric::v1::ModelDescription* response) override;

  // Upper bounds (µs) of the latency histogram's buckets; one more bucket holds the rest.
  static constexpr std::array<double, 12> kLatencyBoundsUs{10, 20, 50, 100, 200, 500, 1e3, 2e3, 5e3, 1e4, 1e5, 1e6};
  struct Counters {
    std::atomic<long long> requests{0}, points{0}, errors{0};
    std::atomic<int> in_flight{0};  // handlers running now; a drain waits for zero
    std::atomic<long long> abandoned{0};  // stopped part-way: deadline passed or call cancelled
    std::atomic<long long> streams{0};    // EvaluateStream calls opened
    std::atomic<long long> fast_points{0};  // answered by a fast evaluator
    std::atomic<long long> refused_busy{0};   // refused: the memory for calls in flight was taken
    std::atomic<long long> refused_streams{0};  // streams refused: --max-streams were open
    std::atomic<long long> stalled_streams{0};  // streams cancelled: their answer was not taken in time
    std::atomic<int> open_streams{0};
    std::array<std::atomic<long long>, kLatencyBoundsUs.size() + 1> latency{};
  };
  const Counters& counters() const { return counters_; }

  // OK while the caller still waits after `done` of `total` points; otherwise why it is gone.
  using CallerCheck = std::function<grpc::Status(int done, int total)>;
  // Everything an Evaluate does after authorisation, without a gRPC call around it (the request
  // fuzzer drives this): validates the request, evaluates it in chunks, asking `gone_check`
  // between chunks (empty: the caller always waits). Throws only what a model throws.
  grpc::Status evaluate(const mufric::v1::EvaluateRequest& request, mufric::v1::EvaluateResponse& response,
                        const CallerCheck& gone_check = {});
  const MemoryBudget& memory() const { return memory_; }

 private:
  class StreamReactor;
  class UnaryReactor;
  grpc::Status authorise(const grpc::CallbackServerContext& context) const;
  // A reactor already finished with UNAUTHENTICATED, or nullptr when the call may proceed.
  grpc::ServerUnaryReactor* refuse_unless_authorised(grpc::CallbackServerContext* context);
  // Reserves the memory the call will hold until its answer is sent (`held`), or refuses it with
  // RESOURCE_EXHAUSTED and the retry hint wire::kRetryAfterKey.
  grpc::Status admit(grpc::CallbackServerContext& context, const mufric::v1::EvaluateRequest& request,
                     MemoryBudget::Reservation& held);
  // Counts the request, admits it, evaluates it, counts an error; never throws.
  // `context` gives the call's deadline and cancellation, checked between chunks of points.
  grpc::Status handle(grpc::CallbackServerContext& context, const mufric::v1::EvaluateRequest& request,
                      mufric::v1::EvaluateResponse& response, MemoryBudget::Reservation& held);

  const ModelRegistry& registry_;
  ServiceLimits limits_;
  Counters counters_;
  MemoryBudget memory_;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
};

}  // namespace mufric::server
