// serve: the gRPC friction service.
#include <cstdio>
#include <memory>

#include "app/commands.hpp"
#include "client/friction_client.hpp"
#include "common/error.hpp"
#include "common/wording.hpp"
#include "server/server.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric::app {

void add_status_command(CLI::App& app) {
  auto uri = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("status", "Counters and latency histogram of a running server");
  cmd->add_option("server", *uri, "grpc://host:port (or grpcs://; token and certificates from MUFRIC_* variables)")
      ->required();
  cmd->callback([uri] {
    const client::ServerStatus s = client::server_status(*uri);
    std::printf("mufric %s, up %.1f s, %s: %lld requests, %lld points, %lld errors "
                "(%lld abandoned at their deadline), %lld in flight, %lld streams opened; %lld points answered by "
                "fast evaluators\n",
                s.code_version.c_str(), s.uptime_seconds,
                count_of(s.evaluation_threads, "evaluation thread", "evaluation threads").c_str(), s.requests, s.points, s.errors,
                s.abandoned, s.in_flight, s.streams, s.fast_points);
    std::printf("memory for calls in flight: %.1f of %s MB in use; %lld calls refused while it was taken; %lld streams "
                "open, %lld refused over --max-streams, %lld cancelled with their answer not taken\n",
                static_cast<double>(s.memory_in_use_bytes) / (1024.0 * 1024.0),
                s.memory_limit_bytes > 0 ? std::to_string(s.memory_limit_bytes / (1024 * 1024)).c_str() : "unlimited",
                s.refused_busy, s.open_streams, s.refused_streams, s.stalled_streams);
    std::printf("server-side evaluation time:\n");
    for (size_t i = 0; i < s.latency_counts.size(); ++i) {
      if (i < s.latency_bounds_us.size()) {
        std::printf("  <= %8.0f us  %lld\n", s.latency_bounds_us[i], s.latency_counts[i]);
      } else {
        std::printf("  >  %8.0f us  %lld\n", s.latency_bounds_us.back(), s.latency_counts[i]);
      }
    }
    for (const auto& m : s.models) std::printf("model %s\n", m.c_str());
  });
}

void add_service_commands(CLI::App& app) {
  add_status_command(app);
  auto o = std::make_shared<server::ServerOptions>();
  auto* cmd = app.add_subcommand("serve", "Serve every model file (*.h5) of a directory over gRPC");
  const std::string shipped = shipped_models_directory();
  cmd->add_option("--models", o->models_directory,
                  "Directory of model files; the name of a model is its file stem (default: the shipped models, " +
                      (shipped.empty() ? std::string("none found") : shipped) + ")");
  cmd->add_option("--listen", o->listen, "Address to listen on (port 0: any free port)")->capture_default_str();
  cmd->add_option("--poll", o->poll_seconds, "Seconds between rescans of the directory for new or changed files")
      ->capture_default_str()->check(FiniteRange(0.05, 3600.0));
  cmd->add_option("--max-message-mb", o->max_message_mb, "Largest request or response, MB")->capture_default_str()
      ->check(CLI::Range(1, 2000));
  cmd->add_option("--max-points", o->max_points, "Most points in one request")->capture_default_str()
      ->check(CLI::Range(1LL, 100'000'000LL));
  cmd->add_option("--max-memory-mb", o->max_memory_mb,
                  "The server's memory, MB: the models at start, gRPC's buffers (an eighth) and calls in flight (the "
                  "rest). A call that does not fit is refused with RESOURCE_EXHAUSTED and a retry hint, which mufric's "
                  "clients follow. 0: no limit")
      ->capture_default_str()->check(CLI::Range(0, 1'000'000));
  cmd->add_option("--max-streams", o->max_streams, "EvaluateStream calls open at once; more are refused (0: no limit)")
      ->capture_default_str()->check(CLI::Range(0, 1'000'000));
  cmd->add_option("--stream-write-seconds", o->stream_write_seconds,
                  "A stream whose client has not taken an answer within this is cancelled (0: never)")
      ->capture_default_str()->check(FiniteRange(0.0, 86400.0));
  cmd->add_option("--threads", o->threads,
                  "Cores evaluation may use (0: all the CPU affinity allows, at most OMP_NUM_THREADS). A batch "
                  "running alone uses them all; k concurrent batches share them, max(1, threads/k) each")
      ->capture_default_str()->check(CLI::Range(0, 4096));
  cmd->add_option("--drain", o->drain_seconds, "Seconds requests in flight get on SIGTERM")->capture_default_str()
      ->check(FiniteRange(0.0, 3600.0));
  cmd->add_option("--ready-file", o->ready_file, "Write the bound address here once serving (for scripts)");
  cmd->add_option("--token-file", o->token_file, "Require 'authorization: Bearer <token>' with the token in this file")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-cert", o->tls_cert, "PEM certificate chain: serve TLS")->check(CLI::ExistingFile);
  cmd->add_option("--tls-key", o->tls_key, "PEM private key of --tls-cert")->check(CLI::ExistingFile);
  cmd->add_option("--tls-client-ca", o->tls_client_ca, "PEM CA: mutual TLS, clients need a certificate it signed")
      ->check(CLI::ExistingFile);
  cmd->add_option("--log-uncertain", o->uncertain_log_directory,
                  "Append queries whose 95 % interval is wider than --uncertain-width, or that lie outside the model's "
                  "box, to DIR/<model>.csv: candidate points for mufric dataset refine --candidates [--grow-box]. "
                  "Counts of outside queries per input and side go to DIR/<model>.outside.json (makes every call "
                  "compute the std)");
  cmd->add_option("--uncertain-width", o->uncertain_width, "Interval width (in mu) above which a query is logged")
      ->capture_default_str()->check(FiniteRange(1e-9, 1e9));
  cmd->add_option("--uncertain-max-rows", o->uncertain_max_rows, "Most logged queries in a model's file: a full DIR/<model>.csv is renamed <model>.csv.1 (replacing the one "
                  "before) and a new one begun")->capture_default_str()
      ->check(CLI::Range(1LL, 1'000'000'000LL));
  cmd->footer("Plaintext unless --tls-cert/--tls-key; bind to loopback unless the network is trusted. SIGHUP rescans the models now, by\n"
              "content; a bad new file is refused, and a deleted file logged, while the loaded version keeps serving. grpc.health.v1 and\n"
              "server reflection are on. Logs go to stderr, one line per event. A call whose deadline passes (or that\n"
              "the client cancels) stops within a few thousand points and answers DEADLINE_EXCEEDED (CANCELLED).");
  cmd->callback([o, shipped] {
    if (o->models_directory.empty()) {
      o->models_directory = shipped;
      if (o->models_directory.empty()) {
        throw Error("serve: no --models directory given and no shipped models found (set MUFRIC_MODELS_DIR)");
      }
      std::fprintf(stderr, "serving the shipped models in %s (--models DIR serves another directory)\n",
                   o->models_directory.c_str());
    }
    server::run_server(*o);
  });
}

}  // namespace mufric::app
