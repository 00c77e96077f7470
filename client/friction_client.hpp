#pragma once
// The meso-code side: one interface, two transports chosen by URI.
//   grpc://host:port/model   a mufric server (channel reuse, deadlines, retry with backoff on
//                            UNAVAILABLE, automatic chunking under the message limit)
//   grpcs://host:port/model  the same over TLS (mutual TLS with a client certificate)
//   file:///path/model.h5    the same model evaluated in-process, no server (or a plain path, or a
//                            shipped model's name: "dry_default")
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/error.hpp"
#include "surrogate/core/friction_model.hpp"

namespace mufric::client {

// The block itself is malformed (an input the model needs is missing, arrays of unequal length):
// retrying cannot help, the caller must fix the call. Every other failure is a plain Error.
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

// One block of contact points, structure-of-arrays, SI; null for inputs not sent.
struct Block {
  size_t points = 0;
  const double* contact_pressure = nullptr;  // Pa
  const double* sliding_velocity = nullptr;  // m/s
  const double* temperature = nullptr;       // K
  const double* fibre_angle = nullptr;       // rad

  // The field that carries a named model input, or nullptr for a name the wire does not carry:
  //   if (auto field = Block::field_for(name)) block.*field = values;
  static const double* Block::*field_for(std::string_view name) {
    if (name == input_name::contact_pressure) return &Block::contact_pressure;
    if (name == input_name::sliding_velocity) return &Block::sliding_velocity;
    if (name == input_name::temperature) return &Block::temperature;
    if (name == input_name::fibre_angle) return &Block::fibre_angle;
    return nullptr;
  }
};

struct Answer {
  std::string model, version;
  std::vector<double> mu, std, lo, hi;  // std/lo/hi empty unless requested
  std::vector<double> gradient;         // row-major points × gradient_inputs, if requested
  // If requested (EvaluationRequest::patch_std) and the model has one: the per-draw standard deviation
  // of μ at each point, how much one contact patch's μ scatters about the mean; empty otherwise.
  std::vector<double> patch_std;
  std::vector<std::string> gradient_inputs;
  std::vector<PointStatus> status;
  long long fast_points = 0;  // answered by the model's fast evaluator; the rest by the exact model
  long long range_clipped = 0;  // points whose μ or interval was clipped to the model's physical μ range
  // "" when every point was answered; else the first point without an answer (INVALID_INPUT or
  // OUT_OF_BOX, numbered in this block), which input and why, and how many more there are.
  std::string message;
};

struct ModelInfo {
  std::string name, version, kind;
  InputSpace inputs;
  bool has_uncertainty = false;
  std::string summary;
  bool has_patch_scatter = false;  // answers EvaluationRequest::patch_std
  // A calibrated model's calibration (DescribeModel's `calibration`): what it was calibrated on, each
  // posterior coordinate's mean, SD and 95 % interval (SI), the interval's parts at the box centre.
  std::optional<CalibrationDescription> calibration;
  // The model's own policy outside its box (a request's Extrapolation::model_default means this one).
  Extrapolation extrapolation = Extrapolation::clamp;
};

struct Options {
  double deadline_seconds = 30.0;   // per call
  int retries = 4;                  // on UNAVAILABLE, with exponential backoff
  double first_backoff_seconds = 0.05;
  long long chunk_points = 65536;   // larger blocks are split into several calls (at a multiple of 128, from 128 up)
  int max_message_mb = 64;
  // Send blocks over one long-lived EvaluateStream (one block per increment) instead of one unary
  // call each; a broken stream is reopened under the same retry policy. Streams carry no deadline.
  bool streaming = false;
  // Security; each empty field falls back to an environment variable, so C and Fortran callers
  // configure it without code: MUFRIC_TOKEN, MUFRIC_TLS_CA, MUFRIC_TLS_CERT, MUFRIC_TLS_KEY.
  std::string token;          // sent as "authorization: Bearer <token>"
  std::string tls_ca_file;    // PEM roots to verify the server (grpcs://); empty: the system's
  std::string tls_cert_file;  // PEM client certificate chain and key, for mutual TLS
  std::string tls_key_file;
  // file:// only: parse the model file in a child process first (surrogate/models/model_file.hpp
  // load_model_isolated), so a corrupt file is an Error instead of a crash of this process. For
  // command-line tools; a meso code's own process (MPI, many threads) should not fork.
  bool isolate_file_parsing = false;
  // For the C ABI's and Fortran's calls (C++ callers set them per call in EvaluationRequest): the
  // tolerances a fast evaluator must meet to answer; 0 (either): the exact model only.
  double mu_tolerance = EvaluationRequest{}.mu_tolerance;
  double std_tolerance = EvaluationRequest{}.std_relative_tolerance;
  Extrapolation extrapolation = Extrapolation::model_default;  // raw, clamp or refuse outside the box
  // Points without an answer (INVALID_INPUT, OUT_OF_BOX) get this finite value in every output (μ,
  // σ, lo, hi, gradient) instead of NaN: a code that traps FE_INVALID must never be handed a NaN,
  // and its status array still says which points these are. Applied to the Answer by both transports.
  std::optional<double> fill;
  // μ of a point without an answer, over `fill`: the value a meso code would use there anyway (its
  // former constant μ), so that a refused point neither poisons nor reverses its friction force
  // (fill=-1 did, taken for μ). Its σ, lo and hi stay NaN or `fill`; its status says it was not answered.
  std::optional<double> fallback_mu;
  // file:// only: log the model's uncertain and out-of-box queries as `serve --log-uncertain DIR` does,
  // into DIR/<model file's stem>.csv and .outside.json, which `mufric learn --log` and `dataset refine
  // --candidates` read; a meso code evaluating in-process needs no server for the learner to follow
  // it. Every log_every-th call is logged (each logged call computes the predictive σ, which a
  // clamped point pays for with the model at the real point: milliseconds for a calibrated model).
  // Over grpc:// the server logs (`serve --log-uncertain`): refused here.
  std::string log_uncertain_directory;
  double uncertain_width = 0.05;           // the 95 % interval's width in μ above which a query is logged
  long long uncertain_max_rows = 100'000;  // a full file is renamed <stem>.csv.1, as the server's
  long long log_every = 1;
  // grpc:// only: a TCP connection of this client's own. Without it gRPC shares one connection among
  // every client of the process with the same target and options (what a meso code wants; a load
  // generator measuring N connections does not).
  bool own_connection = false;
};
// The largest fallback_mu accepted: no measured dry friction coefficient reaches it.
inline constexpr double kLargestFallbackMu = 10.0;

// Options from text, for the C ABI and Fortran (and configuration files): "key=value" pairs separated
// by commas, semicolons or blanks, e.g. "deadline=2, retries=1, stream=1, token=abc".
// Keys: deadline (s), retries, backoff (s, the first), chunk_points, max_message_mb, stream (0/1),
// token, tls_ca, tls_cert, tls_key (PEM file paths), mu_tolerance, std_tolerance (0: exact model),
// extrapolation (raw, clamp or refuse; default: the model's own), fill (a finite number for the outputs
// of points without an answer; default: NaN), fallback_mu (their μ, 0 to 10, over fill), log_uncertain
// (a directory, file:// only), uncertain_width, uncertain_max_rows, log_every. Starts from `base`; throws InvalidArgument
// naming the key or value it cannot use.
Options parse_options(std::string_view text, Options base = {});

// Threads: evaluate() and describe() may be called from many threads at once on one client (an
// OpenMP or MPI + OpenMP meso code sharing one handle). In-process, every call evaluates on its
// calling thread when called from inside a parallel region of two or more threads or while another
// call is running, so the caller's cores are not oversubscribed; over gRPC, unary calls run concurrently and a
// streaming client serialises its one stream (open one client per thread for parallel streams).
// Creating and destroying a client is not concurrent with its use.
class FrictionClient {
 public:
  virtual ~FrictionClient() = default;
  // Throws InvalidArgument for a malformed block, mufric::Error for anything else (unknown model,
  // server unreachable); the message names the problem.
  virtual Answer evaluate(const Block& block, const EvaluationRequest& what) = 0;
  virtual ModelInfo describe() = 0;
};

std::unique_ptr<FrictionClient> connect(const std::string& uri, const Options& options = {});

struct ServerStatus {
  std::string code_version;
  double uptime_seconds = 0.0;
  long long requests = 0, points = 0, errors = 0, in_flight = 0;
  long long abandoned = 0;          // evaluations stopped because the caller's deadline passed
  long long streams = 0;            // EvaluateStream calls opened (their messages are in requests)
  long long fast_points = 0;        // points answered by a fast evaluator
  int evaluation_threads = 0;       // cores one batch may use when it runs alone
  std::vector<double> latency_bounds_us;  // histogram of server-side evaluation time
  std::vector<long long> latency_counts;  // one more than bounds: the last is unbounded
  std::vector<std::string> models;        // "name version kind"
  // serve's memory and stream limits (friction.proto ServerStatus; 0 limit: none).
  long long memory_limit_bytes = 0, memory_in_use_bytes = 0, refused_busy = 0;
  long long open_streams = 0, refused_streams = 0, stalled_streams = 0;
};

// Counters of a server: "grpc://host:port" or "grpcs://host:port" (a model path is ignored).
ServerStatus server_status(const std::string& uri, const Options& options = {});

}  // namespace mufric::client
