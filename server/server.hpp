#pragma once
// `mufric serve`: runs the FrictionService until SIGTERM/SIGINT (graceful drain), loading a model
// when its file appears or changes (polled; SIGHUP rescans by content at once).
#include <memory>
#include <string>

#include <grpcpp/security/server_credentials.h>

namespace mufric::server {

struct ServerOptions {
  std::string models_directory;
  std::string listen = "127.0.0.1:50051";
  double poll_seconds = 1.0;          // directory rescan period
  int max_message_mb = 64;            // receive limit; 10⁵ points × 4 doubles needs ~3.2 MB
  long long max_points = 1'000'000;   // per request
  // The process's memory, MB: what the models take at start, gRPC's transport buffers (an eighth,
  // a grpc::ResourceQuota) and the calls in flight (the rest; a call that does not fit waits for
  // its client's retry). 0: no limit.
  int max_memory_mb = 512;
  int max_streams = 256;              // EvaluateStream calls open at once
  double stream_write_seconds = 30.0;  // an answer not taken by its client within this cancels the stream
  double drain_seconds = 5.0;         // requests in flight get this long on shutdown
  int threads = 0;                    // cores for evaluation; 0: all this process may use (usable_cores())
  std::string ready_file;             // written with the bound address once serving (for scripts)
  std::string token_file;             // bearer token required of every client (file, not argv)
  std::string tls_cert, tls_key;      // PEM server certificate chain and key: TLS instead of plaintext
  std::string tls_client_ca;          // PEM CA: mutual TLS, clients must present a certificate it signed
  std::string uncertain_log_directory;  // log wide-interval queries per model here (empty: off)
  double uncertain_width = 0.05;      // width of the 95 % interval in μ above which a query is logged
  long long uncertain_max_rows = 100'000;  // per model
};

// Plaintext, TLS or mutual TLS from the options; throws Error naming an unreadable file.
std::shared_ptr<grpc::ServerCredentials> server_credentials(const ServerOptions& options);
// The whole content of a file; throws Error naming it (`what` says which option it came from).
std::string read_text_file(const std::string& path, const std::string& what);

// Blocks until a termination signal. Throws mufric::Error if the directory or address is unusable.
void run_server(const ServerOptions& options);

}  // namespace mufric::server
