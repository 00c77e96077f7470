#include "server/server.hpp"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/resource_quota.h>
#include <malloc.h>
#include <netdb.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include "common/environment.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/version.hpp"
#include "common/wording.hpp"
#include "server/friction_service.hpp"

namespace mufric::server {
namespace {

// After the last evaluation has finished, replies get this long to leave before connections close.
constexpr int kReplyFlushMs = 200;

// The transport's share of --max-memory-mb: a grpc::ResourceQuota, which under pressure closes idle
// connections and then cancels streams (gRPC 1.51 lib/resource_quota/memory_quota.cc reclaimers).
constexpr int kTransportShareDivisor = 8;
// Less than this left for calls in flight after the models and the transport: refused at start.
constexpr double kLeastRequestMemoryMb = 32.0;
// Allocations from this size on are mmapped and go back to the system when freed. glibc's default
// threshold grows with every large block freed (up to 32 MB), after which answers' arrays came from
// the arenas and stayed resident: 1015 MB idle after a burst (bench/studies/server_memory/README.md, "The server's memory").
constexpr int kMmapThresholdBytes = 1 << 20;

double resident_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

// The memory a busy spell freed (answers, gRPC's transport buffers of a burst of streams, which the
// memory budget does not count) goes back once the service is idle again.
void give_back_idle_memory(const FrictionService& service, IdleTrimmer& trimmer) {
  const auto& c = service.counters();
  trimmer.poll(c.requests.load() + c.streams.load(), c.in_flight.load() == 0 && service.memory().in_use() == 0);
}

void log_line(const std::string& level, const std::string& message) {
  std::fprintf(stderr, "%s level=%s msg=\"%s\"\n", utc_timestamp().c_str(), level.c_str(), message.c_str());
  std::fflush(stderr);
}

constexpr long kLargestPort = 65535;

struct ListenAddress {
  std::string host;  // an IPv6 address without its brackets
  std::string port;  // decimal, 0 to kLargestPort; 0: any free port
};

Error listen_error(const std::string& listen, const std::string& why) { return Error("--listen " + listen + ": " + why); }

// "host:port" or "[IPv6]:port", checked here: gRPC takes "nonsense" or port 99999 apart only in a raw
// log line of its own, after it has started.
ListenAddress parse_listen_address(const std::string& listen) {
  const std::string expected = " (expected host:port, e.g. 127.0.0.1:50051; port 0: any free port)";
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos) {
    const bool digits_only = !listen.empty() && std::all_of(listen.begin(), listen.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
    if (digits_only) throw listen_error(listen, "a port alone; give host:port, e.g. 127.0.0.1:" + listen + " (loopback) or 0.0.0.0:" + listen + " (every interface)");
    throw listen_error(listen, "no port" + expected);
  }
  ListenAddress address{listen.substr(0, colon), listen.substr(colon + 1)};
  if (address.host.size() >= 2 && address.host.front() == '[' && address.host.back() == ']') {
    address.host = address.host.substr(1, address.host.size() - 2);
  } else if (address.host.find(':') != std::string::npos) {
    throw listen_error(listen, "an IPv6 address goes in brackets, e.g. [::1]:50051");
  }
  if (address.host.empty()) throw listen_error(listen, "no host" + expected);
  const bool digits_only = !address.port.empty() && std::all_of(address.port.begin(), address.port.end(),
                                                                 [](unsigned char c) { return std::isdigit(c) != 0; });
  // More than 6 digits cannot be a port and would overflow stol.
  if (!digits_only || address.port.size() > 6 || std::stol(address.port) > kLargestPort) {
    throw listen_error(listen, "the port must be a number from 0 to " + std::to_string(kLargestPort) + expected);
  }
  return address;
}

// 127.0.0.0/8, ::1 and "localhost": a token sent there never leaves the machine.
bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// Binds a socket to every address the host resolves to, as gRPC will, and closes it again, so that a
// port in use or a host that is not this machine's is an error naming --listen, not gRPC's raw log
// lines. SO_REUSEADDR as gRPC sets it (connections in TIME_WAIT are no objection), no SO_REUSEPORT:
// a server listening there is.
void check_listen_address(const std::string& listen, const ListenAddress& address) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (const int rc = getaddrinfo(address.host.c_str(), address.port.c_str(), &hints, &found); rc != 0) {
    throw listen_error(listen, "cannot resolve '" + address.host + "': " + gai_strerror(rc));
  }
  const std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> addresses(found, &freeaddrinfo);
  int first_error = 0;
  bool any_bound = false;
  for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {  // a family this machine lacks (no IPv6): gRPC passes it over too
      if (first_error == 0) first_error = errno;
      continue;
    }
    const int on = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    const bool bound = ::bind(fd, a->ai_addr, a->ai_addrlen) == 0;
    const int error = errno;
    ::close(fd);
    if (bound) {
      any_bound = true;
    } else if (error == EADDRINUSE) {
      throw listen_error(listen, "the port is in use (another server listens there?)");
    } else if (first_error == 0) {
      first_error = error;
    }
  }
  // gRPC serves on the addresses it can bind ("localhost" on a machine without IPv6: 127.0.0.1 only).
  if (any_bound) return;
  if (first_error == EADDRNOTAVAIL) throw listen_error(listen, "'" + address.host + "' is not an address of this machine");
  if (first_error == EACCES) throw listen_error(listen, "permission denied (ports below 1024 need privileges)");
  throw listen_error(listen, std::string("cannot listen there: ") + std::strerror(first_error));
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
  check_listen_address(options.listen, parse_listen_address(options.listen));
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
  if (registry.all().empty()) {
    log_line("warning", "no model in " + options.models_directory +
                            " yet: every Evaluate answers NOT_FOUND until a valid *.h5 appears there");
  }
  std::string token;
  if (!options.token_file.empty()) {
    token = read_text_file(options.token_file, "--token-file");
    token.erase(token.find_last_not_of(" \t\r\n") + 1);
    if (token.empty()) throw Error("--token-file: '" + options.token_file + "' is empty");
    if (options.tls_cert.empty() && !is_loopback(parse_listen_address(options.listen).host)) {
      log_line("warning", "--token-file over plaintext on " + options.listen +
                              ": the token crosses the network in the clear; give --tls-cert/--tls-key, or listen on loopback");
    }
  }
  const int threads = options.threads > 0 ? options.threads : usable_cores();
  mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes);
  const double start_mb = resident_mb();
  const double transport_mb = options.max_memory_mb / static_cast<double>(kTransportShareDivisor);
  const double request_mb = options.max_memory_mb - start_mb - transport_mb;
  if (options.max_memory_mb > 0 && request_mb < kLeastRequestMemoryMb) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "--max-memory-mb %d: the models take %.0f MB at start and the transport %.0f MB, which leaves %.0f MB "
                  "for calls in flight; give at least %.0f, or 0 for no limit",
                  options.max_memory_mb, start_mb, transport_mb, request_mb,
                  std::ceil((start_mb + kLeastRequestMemoryMb) * kTransportShareDivisor / (kTransportShareDivisor - 1)));
    throw Error(text);
  }
  std::unique_ptr<UncertainQueryLog> uncertain_log;
  if (!options.uncertain_log_directory.empty()) {
    uncertain_log = std::make_unique<UncertainQueryLog>(options.uncertain_log_directory, options.uncertain_width,
                                                        options.uncertain_max_rows);
  }
  FrictionService service(registry, {.max_points_per_request = options.max_points,
                                     .bearer_token = token,
                                     .evaluation_threads = threads,
                                     .uncertain_log = uncertain_log.get(),
                                     .request_memory_bytes = options.max_memory_mb > 0
                                                                 ? static_cast<std::size_t>(request_mb * 1024 * 1024)
                                                                 : 0,
                                     .max_streams = options.max_streams,
                                     .stream_write_seconds = options.stream_write_seconds});

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  // gRPC sets SO_REUSEPORT by default: a second server on a port in use then started anyway, and the
  // kernel handed each connection to one of the two at random.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  int bound_port = 0;
  builder.AddListeningPort(options.listen, server_credentials(options), &bound_port);
  builder.SetMaxReceiveMessageSize(options.max_message_mb * 1024 * 1024);
  builder.SetMaxSendMessageSize(options.max_message_mb * 1024 * 1024);
  if (options.max_memory_mb > 0) {
    grpc::ResourceQuota quota("mufric serve transport");
    quota.Resize(static_cast<std::size_t>(transport_mb * 1024 * 1024));
    builder.SetResourceQuota(quota);
  }
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  // check_listen_address found the port free: taken since, or refused for a reason gRPC logged above.
  if (!server || bound_port == 0) throw listen_error(options.listen, "cannot listen there");
  const std::string host = options.listen.substr(0, options.listen.rfind(':'));
  const std::string address = host + ":" + std::to_string(bound_port);
  const std::string security = options.tls_cert.empty()           ? "plaintext"
                               : options.tls_client_ca.empty()     ? "TLS"
                                                                   : "mutual TLS";
  log_line("info", "mufric " + code_version() + " serving " + registry.names() + " on " + address + " (" + security +
                       (token.empty() ? "" : ", bearer token required") + ", " +
                       count_of(threads, "evaluation thread", "evaluation threads") + ")");
  if (options.max_memory_mb > 0) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "memory: %d MB (--max-memory-mb): %.0f MB at start, %.0f MB for the transport, %.0f MB for calls in "
                  "flight; at most %d streams, each answer taken within %g s",
                  options.max_memory_mb, start_mb, transport_mb, request_mb, options.max_streams,
                  options.stream_write_seconds);
    log_line("info", text);
  }
  if (!options.ready_file.empty()) std::ofstream(options.ready_file) << address << "\n";

  std::mutex mutex;
  std::condition_variable wake;
  bool stopping = false;
  IdleTrimmer trimmer;
  std::thread poller([&] {
    std::unique_lock lock(mutex);
    while (!stopping) {
      wake.wait_for(lock, std::chrono::duration<double>(options.poll_seconds));
      if (stopping) break;
      lock.unlock();
      registry.refresh();
      give_back_idle_memory(service, trimmer);
      // The query counts a learner reads (NAME.outside.json) lag the log by at most a poll.
      if (uncertain_log) uncertain_log->flush();
      lock.lock();
    }
  });
  while (true) {
    int signal_number = 0;
    sigwait(&signals, &signal_number);
    if (signal_number == SIGHUP) {
      log_line("info", "SIGHUP: rescanning the models by content");
      registry.refresh(ModelRegistry::Rescan::kByContent);
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
                       " points, " + std::to_string(c.errors.load()) + " errors (" +
                       std::to_string(c.refused_busy.load()) + " refused while the memory for calls in flight was taken, " +
                       std::to_string(c.refused_streams.load()) + " streams refused over --max-streams, " +
                       std::to_string(c.stalled_streams.load()) + " streams cancelled whose answer was not taken)");
}

}  // namespace mufric::server
