#include "client/friction_client.hpp"

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <atomic>
#include <mutex>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <random>
#include <chrono>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/uncertain_log.hpp"
#include "common/units.hpp"
#include "mufric/v1/friction.grpc.pb.h"
#include "proto/wire_codec.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric::client {
namespace {

const double* input_pointer(const Block& block, const std::string& name) {
  const auto field = Block::field_for(name);
  return field ? block.*field : nullptr;
}

// Options::fill and Options::fallback_mu: the outputs of a point without an answer get the caller's
// values instead of NaN (fill: every output; fallback_mu: μ, over fill). Chosen by the status, not by
// testing the value: isnan is quiet, but the caller may run with FE_INVALID trapping, and nothing
// here should even look at a NaN in a way that could raise it.
struct UnansweredValues {
  std::optional<double> fill;
  std::optional<double> fallback_mu;
};

void fill_unanswered(Answer& answer, const UnansweredValues& options) {
  if (!options.fill && !options.fallback_mu) return;
  const size_t points = answer.status.size();
  const size_t gradient_width = points > 0 ? answer.gradient.size() / points : 0;
  for (size_t i = 0; i < points; ++i) {
    if (!has_no_answer(answer.status[i])) continue;
    if (options.fill) {
      for (auto* output : {&answer.mu, &answer.std, &answer.lo, &answer.hi, &answer.patch_std}) {
        if (i < output->size()) (*output)[i] = *options.fill;
      }
      std::fill_n(answer.gradient.begin() + static_cast<std::ptrdiff_t>(i * gradient_width), gradient_width,
                  *options.fill);
    }
    if (options.fallback_mu && i < answer.mu.size()) answer.mu[i] = *options.fallback_mu;
  }
}

// The server's retry hint when it refused a call for want of memory or streams (ms), else nullopt.
// gRPC's transport sheds calls itself when its buffers exceed the server's quota (RST_STREAM
// ENHANCE_YOUR_CALM, HTTP/2 error 11; grpc 1.51 chttp2 destructive_reclaimer): retried the same way.
std::optional<double> busy_retry_ms(const grpc::ClientContext& context, const grpc::Status& status) {
  if (status.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED) return std::nullopt;
  if (status.error_message().find(wire::kTransportShedMessage) != std::string::npos) return wire::kTransportShedRetryMs;
  const auto& trailers = context.GetServerTrailingMetadata();
  const auto hint = trailers.find(wire::kRetryAfterKey);
  if (hint == trailers.end()) return std::nullopt;
  double ms = 0.0;
  const auto [end, error] = std::from_chars(hint->second.data(), hint->second.data() + hint->second.size(), ms);
  if (error != std::errc() || !(ms >= 0.0)) return std::nullopt;
  return ms;
}

// Retries of calls the server refused as busy: until the call's deadline, each after the server's
// hint times a factor that grows 1.5x a time from a random start in [1, 2) (full-jitter style,
// Brooker 2015, "Exponential Backoff And Jitter"), so that refused clients do not return together.
class BusyRetry {
 public:
  explicit BusyRetry(double deadline_seconds)
      : end_(std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                    std::chrono::duration<double>(deadline_seconds))),
        factor_(std::uniform_real_distribution<double>(1.0, 2.0)(generator())) {}
  // Sleeps and returns true when there is time for another try.
  bool wait(double hint_ms) {
    const auto pause = std::chrono::duration<double, std::milli>(std::min(hint_ms * factor_, kLongestPauseMs));
    if (std::chrono::steady_clock::now() + pause >= end_) return false;
    std::this_thread::sleep_for(pause);
    factor_ *= 1.5;
    return true;
  }

 private:
  static constexpr double kLongestPauseMs = 1000.0;
  static std::minstd_rand& generator() {
    thread_local std::minstd_rand engine(std::random_device{}());
    return engine;
  }
  std::chrono::steady_clock::time_point end_;
  double factor_;
};

class InProcessClient final : public FrictionClient {
 public:
  InProcessClient(const std::string& path, const Options& options)
      : path_(path),
        model_(options.isolate_file_parsing ? load_model_isolated(path) : load_model(path)),
        unanswered_{options.fill, options.fallback_mu},
        log_every_(options.log_every) {
    if (const std::string why = servable_inputs_violation(input_names(model_->inputs())); !why.empty()) {
      throw Error("model '" + path + "' cannot be evaluated through a client: " + why);
    }
    if (!options.log_uncertain_directory.empty() && model_->has_uncertainty()) {
      log_ = std::make_unique<UncertainQueryLog>(options.log_uncertain_directory, options.uncertain_width,
                                                 options.uncertain_max_rows);
      log_name_ = std::filesystem::path(path).stem().string();
    }
  }

  Answer evaluate(const Block& block, const EvaluationRequest& request) override {
    // Several threads of the caller at once (std::thread, MPI + threads: an OpenMP caller is caught
    // by the model itself): each evaluates on its own thread instead of starting a team per call.
    const CallsInFlight call(in_flight_);
    EvaluationRequest what = request;
    if (call.others_in_flight()) what.max_threads = 1;
    const auto& inputs = model_->inputs();
    QueryBatch x(static_cast<Eigen::Index>(block.points), static_cast<Eigen::Index>(inputs.size()));
    for (size_t j = 0; j < inputs.size(); ++j) {
      const double* values = input_pointer(block, inputs[j].name);
      if (values == nullptr) {
        throw InvalidArgument("model '" + path_ + "' needs input " + inputs[j].name + ", which was not given");
      }
      x.col(static_cast<Eigen::Index>(j)) = Eigen::Map<const Eigen::VectorXd>(values, x.rows());
    }
    const bool logged = log_ && calls_.fetch_add(1) % log_every_ == 0;
    if (logged) what.std = true;
    const Evaluation e = model_->evaluate(x, what);
    if (logged) log_->record(log_name_, inputs, x, e.std);
    Answer a;
    a.model = path_;
    a.mu.assign(e.mu.data(), e.mu.data() + e.mu.size());
    if (request.std) a.std.assign(e.std.data(), e.std.data() + e.std.size());
    a.lo.assign(e.lo.data(), e.lo.data() + e.lo.size());
    a.hi.assign(e.hi.data(), e.hi.data() + e.hi.size());
    a.patch_std.assign(e.patch_std.data(), e.patch_std.data() + e.patch_std.size());
    if (what.gradient) {
      const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = e.gradient;
      a.gradient.assign(rows.data(), rows.data() + rows.size());
      for (const auto& input : inputs) a.gradient_inputs.push_back(input.name);
    }
    a.status = e.status;
    a.fast_points = e.fast_points;
    a.range_clipped = e.range_clipped;
    // the server's words for the same block
    a.message = block_message(inputs, x, a.status, effective_extrapolation(what.extrapolation, model_->default_extrapolation()));
    fill_unanswered(a, unanswered_);
    return a;
  }

  ModelInfo describe() override {
    return {path_,
            "",
            std::string(model_->kind()),
            model_->inputs(),
            model_->has_uncertainty(),
            model_->summary(),
            model_->has_patch_scatter(),
            model_->kind_description().calibration,
            model_->default_extrapolation()};
  }

 private:
  class CallsInFlight {
   public:
    explicit CallsInFlight(std::atomic<int>& count) : count_(count), before_(count_.fetch_add(1)) {}
    ~CallsInFlight() { count_.fetch_sub(1); }
    CallsInFlight(const CallsInFlight&) = delete;
    CallsInFlight& operator=(const CallsInFlight&) = delete;
    bool others_in_flight() const { return before_ > 0; }

   private:
    std::atomic<int>& count_;
    int before_;
  };

  std::string path_;
  std::unique_ptr<FrictionModel> model_;  // evaluation is const and keeps no state: safe from many threads
  UnansweredValues unanswered_;
  std::atomic<int> in_flight_{0};
  std::unique_ptr<UncertainQueryLog> log_;  // Options::log_uncertain_directory; null: no log
  std::string log_name_;                    // the model file's stem, the log's file name
  long long log_every_;
  std::atomic<long long> calls_{0};
};

struct ServerUri {
  std::string target;  // host:port
  std::string model;   // empty when the URI names no model
  bool tls;
};

// "grpc://host:port[/model]" or "grpcs://…"; nothing for other schemes.
std::optional<ServerUri> parse_server_uri(const std::string& uri) {
  for (const std::string scheme : {"grpc://", "grpcs://"}) {
    if (uri.rfind(scheme, 0) != 0) continue;
    const std::string rest = uri.substr(scheme.size());
    const auto slash = rest.find('/');
    return ServerUri{rest.substr(0, slash), slash == std::string::npos ? "" : rest.substr(slash + 1),
                     scheme == "grpcs://"};
  }
  return std::nullopt;
}

std::string setting(const std::string& value, const char* environment_variable) {
  if (!value.empty()) return value;
  const char* from_environment = std::getenv(environment_variable);
  return from_environment ? from_environment : "";
}

std::string file_text(const std::string& path, const char* what) {
  auto text = read_whole_file(path);
  if (!text) throw Error(std::string(what) + ": cannot read '" + path + "'");
  return std::move(*text);
}

std::shared_ptr<grpc::ChannelCredentials> channel_credentials(bool tls, const Options& options) {
  if (!tls) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions ssl;
  const std::string ca = setting(options.tls_ca_file, "MUFRIC_TLS_CA");
  const std::string cert = setting(options.tls_cert_file, "MUFRIC_TLS_CERT");
  const std::string key = setting(options.tls_key_file, "MUFRIC_TLS_KEY");
  if (!ca.empty()) ssl.pem_root_certs = file_text(ca, "TLS CA (tls_ca_file / MUFRIC_TLS_CA)");
  if (cert.empty() != key.empty()) throw Error("a TLS client certificate needs its key, and the key its certificate");
  if (!cert.empty()) {
    ssl.pem_cert_chain = file_text(cert, "TLS client certificate (tls_cert_file / MUFRIC_TLS_CERT)");
    ssl.pem_private_key = file_text(key, "TLS client key (tls_key_file / MUFRIC_TLS_KEY)");
  }
  return grpc::SslCredentials(ssl);
}

class GrpcClient final : public FrictionClient {
 public:
  GrpcClient(const std::string& target, std::string model, bool tls, const Options& options)
      : model_(std::move(model)), tls_(tls), options_(options), token_(setting(options.token, "MUFRIC_TOKEN")) {
    grpc::ChannelArguments arguments;
    arguments.SetMaxReceiveMessageSize(options.max_message_mb * 1024 * 1024);
    arguments.SetMaxSendMessageSize(options.max_message_mb * 1024 * 1024);
    // gRPC's own reconnect backoff starts at 1 s; a restarting server should be found again within
    // the client's retry schedule, so the channel redials on the same time scale.
    const int backoff_ms = std::max(1, static_cast<int>(1000.0 * options.first_backoff_seconds));
    arguments.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, backoff_ms);
    arguments.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, backoff_ms);
    arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, backoff_ms << options.retries);
    // gRPC shares one connection among a process's channels to the same target with the same arguments.
    if (options.own_connection) arguments.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
    channel_ = grpc::CreateCustomChannel(target, channel_credentials(tls, options), arguments);
    stub_ = mufric::v1::FrictionService::NewStub(channel_);
  }

  Answer evaluate(const Block& block, const EvaluationRequest& what) override {
    Answer answer;
    const auto chunk = static_cast<size_t>(wire::bit_stable_piece(options_.chunk_points));
    for (size_t first = 0; first < block.points || first == 0; first += chunk) {
      const size_t count = std::min(chunk, block.points - first);
      const mufric::v1::EvaluateRequest request = make_request(block, first, count, what);
      mufric::v1::EvaluateResponse response;
      if (options_.streaming) {
        exchange_on_stream(request, response);
      } else {
        call("Evaluate", [&](grpc::ClientContext* context) { return stub_->Evaluate(context, request, &response); });
      }
      append(response, first, answer);
      if (block.points == 0) break;
    }
    if (!answer.message.empty() && chunk < block.points) answer.message = whole_block_message(answer);
    fill_unanswered(answer, {options_.fill, options_.fallback_mu});
    return answer;
  }

  ModelInfo describe() override {
    mufric::v1::DescribeModelRequest request;
    request.set_model(model_);
    mufric::v1::ModelDescription d;
    call("DescribeModel", [&](grpc::ClientContext* context) { return stub_->DescribeModel(context, request, &d); });
    ModelInfo info{d.name(), d.version(), d.kind(), wire::decode_inputs(d), d.has_uncertainty(), d.summary(),
                   d.has_patch_scatter(), wire::decode_calibration(d)};
    if (const auto policy = wire::decode_extrapolation(d)) info.extrapolation = *policy;
    return info;
  }

 private:
  // Deadline on every attempt; UNAVAILABLE (server restarting, not yet up) is retried with backoff,
  // a busy server's refusal after its hint until the deadline.
  template <typename Rpc>
  void call(const char* method, Rpc rpc) {
    double backoff = options_.first_backoff_seconds;
    BusyRetry busy(options_.deadline_seconds);
    for (int attempt = 0;; ++attempt) {
      grpc::ClientContext context;
      authorise(context);
      context.set_deadline(std::chrono::system_clock::now() +
                           std::chrono::duration_cast<std::chrono::system_clock::duration>(
                               std::chrono::duration<double>(options_.deadline_seconds)));
      const grpc::Status status = rpc(&context);
      if (status.ok()) return;
      if (const auto hint = busy_retry_ms(context, status); hint && busy.wait(*hint)) {
        --attempt;  // a busy server is not a failed attempt
        continue;
      }
      if (status.error_code() == grpc::StatusCode::UNAVAILABLE && attempt < options_.retries) {
        std::this_thread::sleep_for(std::chrono::duration<double>(backoff));
        backoff *= 2.0;
        continue;
      }
      throw_failure(std::string(method), status);
    }
  }

  // The caller's own mistake (INVALID_ARGUMENT) is told apart from a failure of the service.
  [[noreturn]] void throw_failure(const std::string& method, const grpc::Status& status) const {
    std::string message =
        method + " on model '" + model_ + "' failed (" + code_name(status.error_code()) + "): " + status.error_message();
    // gRPC reports a TLS mismatch as a transport detail of a failed connection ("tcp handshaker
    // shutdown", "Socket closed"): say its likely cause.
    const std::string& detail = status.error_message();
    const bool closed_while_connecting = detail.find("failed to connect") != std::string::npos &&
                                         (detail.find("andshake") != std::string::npos ||
                                          detail.find("Socket closed") != std::string::npos);
    if (status.error_code() == grpc::StatusCode::UNAVAILABLE && closed_while_connecting) {
      message += tls_ ? " (the TLS handshake failed: is the server plaintext (no --tls-cert), or does it not accept "
                        "these certificates (tls_ca; tls_cert/tls_key when it asks for a client certificate)?)"
                      : " (the connection closed while it was being set up: does the server use TLS? then connect "
                        "with grpcs:// and tls_ca)";
    }
    if (status.error_code() == grpc::StatusCode::INVALID_ARGUMENT) throw InvalidArgument(message);
    throw Error(message);
  }

  static std::string code_name(grpc::StatusCode code) {
    switch (code) {
      case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
      case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
      case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
      case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
      case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
      case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
      default: return "status " + std::to_string(static_cast<int>(code));
    }
  }

  mufric::v1::EvaluateRequest make_request(const Block& block, size_t first, size_t count,
                                           const EvaluationRequest& what) const {
    mufric::v1::EvaluateRequest request;
    request.set_model(model_);
    for (const std::string& name : known_input_names()) {
      const auto field = Block::field_for(name);
      const double* values = field ? block.*field : nullptr;
      auto* array = wire::mutable_input_array(request, name);
      if (values && array) array->Assign(values + first, values + first + count);
    }
    wire::encode_options(what, request);
    return request;
  }

  // The server numbers points within its call: for a block split into calls, the first message is
  // renumbered as the block's point and its count of further points made the block's, so the
  // caller reads what an in-process evaluation of the whole block says. The first call with a
  // message comes first (calls go in order), so its first point is the block's first.
  // A block's message tells of a point without an answer before one outside the box (as in-process).
  static void append(const mufric::v1::EvaluateResponse& response, size_t first, Answer& answer) {
    const bool replaces = answer.message.empty() ||
                          (tells_extrapolated(answer.message) && !tells_extrapolated(response.message()));
    if (replaces && !response.message().empty()) {
      answer.message = renumbered(response.message(), first);
    }
    answer.model = response.model();
    answer.version = response.version();
    answer.mu.insert(answer.mu.end(), response.mu().begin(), response.mu().end());
    answer.std.insert(answer.std.end(), response.std().begin(), response.std().end());
    answer.lo.insert(answer.lo.end(), response.lo().begin(), response.lo().end());
    answer.hi.insert(answer.hi.end(), response.hi().begin(), response.hi().end());
    answer.patch_std.insert(answer.patch_std.end(), response.patch_std().begin(), response.patch_std().end());
    answer.gradient.insert(answer.gradient.end(), response.gradient().begin(), response.gradient().end());
    answer.gradient_inputs.assign(response.gradient_inputs().begin(), response.gradient_inputs().end());
    for (const int s : response.status()) answer.status.push_back(static_cast<PointStatus>(s));
    answer.fast_points += static_cast<long long>(response.fast_points());
    answer.range_clipped += static_cast<long long>(response.range_clipped_points());
  }

  // "point 3 OUT_OF_BOX: ..." of a call that started at block point `first`: "point 3+first ...".
  // Anything not in that form (another server's words) is passed on as it is.
  static std::string renumbered(const std::string& message, size_t first) {
    constexpr std::string_view prefix = "point ";
    if (first == 0 || message.rfind(prefix, 0) != 0) return message;
    size_t index = 0;
    const char* digits = message.data() + prefix.size();
    const auto [end, ec] = std::from_chars(digits, message.data() + message.size(), index);
    if (ec != std::errc() || end == digits) return message;
    return std::string(prefix) + std::to_string(index + first) + std::string(end, message.data() + message.size());
  }

  static bool tells_extrapolated(const std::string& message) {
    return message.rfind("point ", 0) == 0 && message.find(" EXTRAPOLATED: ") != std::string::npos;
  }

  // The whole block's count of further unanswered (or extrapolated) points in place of the first call's.
  static std::string whole_block_message(const Answer& answer) {
    const bool extrapolated = tells_extrapolated(answer.message);
    std::string message = answer.message;
    const auto tail = message.rfind(" (and ");
    if (tail != std::string::npos && message.ends_with(extrapolated ? " outside the box)" : " without an answer)")) message.erase(tail);
    const auto counted = extrapolated ? std::count(answer.status.begin(), answer.status.end(), PointStatus::extrapolated)
                                      : std::count_if(answer.status.begin(), answer.status.end(), has_no_answer);
    return message + more_points_tail(counted - 1, extrapolated);
  }

  // One request, one response on the open stream; the stream is (re)opened as needed, and a stream
  // that ends with UNAVAILABLE is retried with backoff like a unary call.
  void exchange_on_stream(const mufric::v1::EvaluateRequest& request, mufric::v1::EvaluateResponse& response) {
    // One stream per handle carries one request at a time: threads sharing the handle take turns
    // (a thread that wants its own stream opens its own handle).
    const std::lock_guard<std::mutex> lock(stream_mutex_);
    double backoff = options_.first_backoff_seconds;
    BusyRetry busy(options_.deadline_seconds);
    for (int attempt = 0;; ++attempt) {
      if (!stream_) {
        stream_context_ = std::make_unique<grpc::ClientContext>();
        authorise(*stream_context_);
        stream_ = stub_->EvaluateStream(stream_context_.get());
      }
      if (stream_->Write(request) && stream_->Read(&response)) return;
      const grpc::Status status = stream_->Finish();
      const auto hint = busy_retry_ms(*stream_context_, status);
      stream_.reset();
      stream_context_.reset();
      if (hint && busy.wait(*hint)) {
        --attempt;  // a busy server is not a failed attempt
        continue;
      }
      if ((status.ok() || status.error_code() == grpc::StatusCode::UNAVAILABLE) && attempt < options_.retries) {
        std::this_thread::sleep_for(std::chrono::duration<double>(backoff));
        backoff *= 2.0;
        continue;
      }
      throw_failure("EvaluateStream", status);
    }
  }

  void authorise(grpc::ClientContext& context) const {
    if (!token_.empty()) context.AddMetadata("authorization", "Bearer " + token_);
  }

  std::string model_;
  bool tls_;  // grpcs://
  Options options_;
  std::string token_;
  std::mutex stream_mutex_;  // guards stream_context_ and stream_
  std::unique_ptr<grpc::ClientContext> stream_context_;
  std::unique_ptr<grpc::ClientReaderWriter<mufric::v1::EvaluateRequest, mufric::v1::EvaluateResponse>> stream_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<mufric::v1::FrictionService::Stub> stub_;
};

}  // namespace

ServerStatus server_status(const std::string& uri, const Options& options) {
  const auto server = parse_server_uri(uri);
  if (!server) throw Error("server URI '" + uri + "': expected grpc://host:port");
  const std::string& target = server->target;
  auto stub =
      mufric::v1::FrictionService::NewStub(grpc::CreateChannel(target, channel_credentials(server->tls, options)));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  const std::string token = setting(options.token, "MUFRIC_TOKEN");
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  mufric::v1::ServerStatus s;
  const grpc::Status status = stub->GetServerStatus(&context, mufric::v1::ServerStatusRequest(), &s);
  if (!status.ok()) throw Error("GetServerStatus on " + target + " failed: " + status.error_message());
  ServerStatus out{s.code_version(), s.uptime_seconds(), static_cast<long long>(s.requests()),
                   static_cast<long long>(s.points()), static_cast<long long>(s.errors()),
                   static_cast<long long>(s.in_flight()), static_cast<long long>(s.abandoned()),
                   static_cast<long long>(s.streams()), static_cast<long long>(s.fast_points()),
                   static_cast<int>(s.evaluation_threads()),
                   {s.latency_bounds_us().begin(), s.latency_bounds_us().end()},
                   {s.latency_counts().begin(), s.latency_counts().end()}, {}};
  for (const auto& m : s.models()) out.models.push_back(m.name() + " " + m.version() + " " + m.kind());
  out.memory_limit_bytes = static_cast<long long>(s.memory_limit_bytes());
  out.memory_in_use_bytes = static_cast<long long>(s.memory_in_use_bytes());
  out.refused_busy = static_cast<long long>(s.refused_busy());
  out.open_streams = static_cast<long long>(s.open_streams());
  out.refused_streams = static_cast<long long>(s.refused_streams());
  out.stalled_streams = static_cast<long long>(s.stalled_streams());
  return out;
}

namespace {

double number_option(const std::string& key, const std::string& value, double lo, double hi) {
  double x = 0.0;
  const auto end = value.data() + value.size();
  const auto [ptr, ec] = std::from_chars(value.data(), end, x);
  if (ec != std::errc() || ptr != end || !std::isfinite(x)) {
    throw InvalidArgument("option " + key + ": '" + value + "' is not a number");
  }
  if (x < lo || x > hi) {
    throw InvalidArgument("option " + key + ": " + value + " is outside [" + std::to_string(lo) + ", " +
                          std::to_string(hi) + "]");
  }
  return x;
}

long long whole_option(const std::string& key, const std::string& value, long long lo, long long hi) {
  const double x = number_option(key, value, static_cast<double>(lo), static_cast<double>(hi));
  if (x != std::floor(x)) throw InvalidArgument("option " + key + ": '" + value + "' is not a whole number");
  return static_cast<long long>(x);
}

bool flag_option(const std::string& key, const std::string& value) {
  if (value == "1" || value == "true" || value == "yes" || value == "on") return true;
  if (value == "0" || value == "false" || value == "no" || value == "off") return false;
  throw InvalidArgument("option " + key + ": '" + value + "' is not 0/1, true/false, yes/no or on/off");
}

}  // namespace

Options parse_options(std::string_view text, Options base) {
  Options o = std::move(base);
  size_t at = 0;
  const auto separator = [](char c) { return c == ',' || c == ';' || c == ' ' || c == '\t' || c == '\n'; };
  while (at < text.size()) {
    while (at < text.size() && separator(text[at])) ++at;
    size_t end = at;
    while (end < text.size() && !separator(text[end])) ++end;
    if (end == at) break;
    const std::string item(text.substr(at, end - at));
    at = end;
    const auto equals = item.find('=');
    if (equals == std::string::npos || equals == 0) {
      throw InvalidArgument("option '" + item + "': expected key=value");
    }
    const std::string key = item.substr(0, equals), value = item.substr(equals + 1);
    if (key == "deadline") {
      o.deadline_seconds = number_option(key, value, 1e-6, 1e7);
    } else if (key == "retries") {
      o.retries = static_cast<int>(whole_option(key, value, 0, 30));
    } else if (key == "backoff") {
      o.first_backoff_seconds = number_option(key, value, 0.0, 60.0);
    } else if (key == "chunk_points") {
      o.chunk_points = whole_option(key, value, 1, 1'000'000'000);
    } else if (key == "max_message_mb") {
      o.max_message_mb = static_cast<int>(whole_option(key, value, 1, 2000));
    } else if (key == "stream") {
      o.streaming = flag_option(key, value);
    } else if (key == "token") {
      o.token = value;
    } else if (key == "tls_ca") {
      o.tls_ca_file = value;
    } else if (key == "tls_cert") {
      o.tls_cert_file = value;
    } else if (key == "tls_key") {
      o.tls_key_file = value;
    } else if (key == "extrapolation") {
      try {
        o.extrapolation = extrapolation_from_string(value);
      } catch (const Error& e) {
        throw InvalidArgument(std::string("option extrapolation: ") + e.what());
      }
    } else if (key == "mu_tolerance") {
      o.mu_tolerance = number_option(key, value, 0.0, 1.0);
    } else if (key == "std_tolerance") {
      o.std_tolerance = number_option(key, value, 0.0, 1.0);
    } else if (key == "fill") {
      constexpr double largest = std::numeric_limits<double>::max();
      o.fill = number_option(key, value, -largest, largest);  // finite: NaN or inf would defeat its purpose
    } else if (key == "fallback_mu") {
      o.fallback_mu = number_option(key, value, 0.0, kLargestFallbackMu);
    } else if (key == "log_uncertain") {
      if (value.empty()) throw InvalidArgument("option log_uncertain: a directory is needed");
      o.log_uncertain_directory = value;
    } else if (key == "uncertain_width") {
      o.uncertain_width = number_option(key, value, 1e-12, 1e6);
    } else if (key == "uncertain_max_rows") {
      o.uncertain_max_rows = whole_option(key, value, 1, 1'000'000'000);
    } else if (key == "log_every") {
      o.log_every = whole_option(key, value, 1, 1'000'000'000);
    } else {
      throw InvalidArgument("option '" + key +
                            "' is unknown (known: deadline, retries, backoff, chunk_points, max_message_mb, stream, "
                            "token, tls_ca, tls_cert, tls_key, mu_tolerance, std_tolerance, extrapolation, fill, fallback_mu, "
                            "log_uncertain, uncertain_width, uncertain_max_rows, log_every)");
    }
  }
  return o;
}

std::unique_ptr<FrictionClient> connect(const std::string& uri, const Options& options) {
  if (const auto server = parse_server_uri(uri)) {
    if (server->model.empty()) {
      throw Error("model URI '" + uri + "': expected " + (server->tls ? "grpcs" : "grpc") + "://host:port/model");
    }
    if (!options.log_uncertain_directory.empty()) {
      throw InvalidArgument("option log_uncertain is for a model evaluated in-process (file://); over gRPC the server "
                            "logs: mufric serve --log-uncertain DIR");
    }
    return std::make_unique<GrpcClient>(server->target, server->model, server->tls, options);
  }
  return std::make_unique<InProcessClient>(model_path_from_uri(uri), options);
}

}  // namespace mufric::client
