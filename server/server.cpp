#include "server/server.hpp"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/version.hpp"
#include "server/friction_service.hpp"

namespace mufric::server {
namespace {

// After the last evaluation has finished, replies get this long to leave before connections close.
constexpr int kReplyFlushMs = 200;

void log_line(const std::string& level, const std::string& message) {
  std::fprintf(stderr, "%s level=%s msg=\"%s\"\n", utc_timestamp().c_str(), level.c_str(), message.c_str());
  std::fflush(stderr);
}

}  // namespace

std::string read_text_file(const std::string& path, const std::string& what) {
  auto text = read_whole_file(path);
  if (!text) throw Error(what + ": cannot read '" + path + "'");
  return std::move(*text);
}

std::shared_ptr<grpc::ServerCredentials> server_credentials(const ServerOptions& options) {
  if (options.tls_cert.empty() != options.tls_key.empty()) throw Error("--tls-cert and --tls-key go together");
  if (options.tls_cert.empty()) {
    if (!options.tls_client_ca.empty()) throw Error("--tls-client-ca needs --tls-cert and --tls-key");
    return grpc::InsecureServerCredentials();
  }
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back(
      {read_text_file(options.tls_key, "--tls-key"), read_text_file(options.tls_cert, "--tls-cert")});
  if (!options.tls_client_ca.empty()) {
    ssl.pem_root_certs = read_text_file(options.tls_client_ca, "--tls-client-ca");
    ssl.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(ssl);
}

void run_server(const ServerOptions& options) {
  if (!std::filesystem::is_directory(options.models_directory)) {
    throw Error("--models: '" + options.models_directory + "' is not a directory");
  }
  // Signals are taken synchronously by one thread; every other thread, gRPC's included, has them blocked.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  ModelRegistry registry(options.models_directory, log_line);
  registry.refresh();
  std::string token;
  if (!options.token_file.empty()) {
    token = read_text_file(options.token_file, "--token-file");
    token.erase(token.find_last_not_of(" \t\r\n") + 1);
    if (token.empty()) throw Error("--token-file: '" + options.token_file + "' is empty");
  }
  const int threads = options.threads > 0 ? options.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::unique_ptr<UncertainQueryLog> uncertain_log;
  if (!options.uncertain_log_directory.empty()) {
    uncertain_log = std::make_unique<UncertainQueryLog>(options.uncertain_log_directory, options.uncertain_width,
                                                        options.uncertain_max_rows);
  }
  FrictionService service(registry, {.max_points_per_request = options.max_points,
                                     .bearer_token = token,
                                     .evaluation_threads = threads,
                                     .uncertain_log = uncertain_log.get()});

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int bound_port = 0;
  builder.AddListeningPort(options.listen, server_credentials(options), &bound_port);
  builder.SetMaxReceiveMessageSize(options.max_message_mb * 1024 * 1024);
  builder.SetMaxSendMessageSize(options.max_message_mb * 1024 * 1024);
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || bound_port == 0) throw Error("--listen: cannot listen on '" + options.listen + "'");
  const std::string host = options.listen.substr(0, options.listen.rfind(':'));
  const std::string address = host + ":" + std::to_string(bound_port);
  const std::string security = options.tls_cert.empty()           ? "plaintext"
                               : options.tls_client_ca.empty()     ? "TLS"
                                                                   : "mutual TLS";
  log_line("info", "mufric " + code_version() + " serving " + registry.names() + " on " + address + " (" + security +
                       (token.empty() ? "" : ", bearer token required") + ", " + std::to_string(threads) +
                       " evaluation threads)");
  if (!options.ready_file.empty()) std::ofstream(options.ready_file) << address << "\n";

  std::mutex mutex;
  std::condition_variable wake;
  bool stopping = false;
  std::thread poller([&] {
    std::unique_lock lock(mutex);
    while (!stopping) {
      wake.wait_for(lock, std::chrono::duration<double>(options.poll_seconds));
      if (stopping) break;
      lock.unlock();
      registry.refresh();
      lock.lock();
    }
  });
  while (true) {
    int signal_number = 0;
    sigwait(&signals, &signal_number);
    if (signal_number == SIGHUP) {
      log_line("info", "SIGHUP: reloading models");
      registry.refresh();
      continue;
    }
    log_line("info", std::string(signal_number == SIGTERM ? "SIGTERM" : "SIGINT") + ": draining");
    break;
  }
  {
    std::lock_guard lock(mutex);
    stopping = true;
  }
  wake.notify_all();
  poller.join();
  // Drain: wait (at most --drain) until no evaluation is running, then shut down with a short grace
  // for the last replies to flush. Shutdown(deadline) alone would wait the whole deadline whenever
  // a client keeps an idle channel open, which meso codes always do.
  const auto drain_end = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.drain_seconds);
  while (service.counters().in_flight.load() > 0 && std::chrono::steady_clock::now() < drain_end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::milliseconds(kReplyFlushMs));
  const auto& c = service.counters();
  log_line("info", "stopped after " + std::to_string(c.requests.load()) + " requests, " + std::to_string(c.points.load()) +
                       " points, " + std::to_string(c.errors.load()) + " errors");
}

}  // namespace mufric::server
