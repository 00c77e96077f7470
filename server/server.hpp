#pragma once
// `mufric serve`: runs the FrictionService until SIGTERM/SIGINT (graceful drain), reloading models
// on SIGHUP and whenever a file in the directory appears, changes or disappears.
#include <string>

namespace mufric::server {

struct ServerOptions {
  std::string models_directory;
  std::string listen = "127.0.0.1:50051";
  double poll_seconds = 1.0;          // directory rescan period
  int max_message_mb = 64;            // receive limit; 10⁵ points × 4 doubles needs ~3.2 MB
  long long max_points = 1'000'000;   // per request
  double drain_seconds = 5.0;         // requests in flight get this long on shutdown
  std::string ready_file;             // written with the bound address once serving (for scripts)
};

// Blocks until a termination signal. Throws mufric::Error if the directory or address is unusable.
void run_server(const ServerOptions& options);

}  // namespace mufric::server
