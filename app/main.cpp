// mufric: friction coefficient μ(p, v, T) with a confidence interval, for meso-scale machining codes.
#include <CLI/CLI.hpp>
#include <H5Cpp.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "common/version.hpp"

namespace {

// How long an idle OpenMP thread spins before it sleeps (libgomp's default: 300 000 spins when the
// wait policy is unset). On a node shared with another CPU-bound process, a thread spinning at a
// barrier holds the core its descheduled team-mate needs: the default micro run took 2–8× its one-core
// time beside one competing process and 9× beside two. 5000 spins keep the idle-machine speed and
// 1.1× beside one (bench/RESULTS.md, "Threads on a busy machine").
constexpr const char* kOpenMpSpinCount = "5000";

// libgomp reads its wait policy once, when it is loaded, so it must be in the environment before
// the process starts: unless the user chose one, set it and start again (once: the second start
// sees it set). A failed exec leaves everything as it was.
void bound_openmp_spinning(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (::setenv("GOMP_SPINCOUNT", kOpenMpSpinCount, 0) != 0) return;
  ::execv("/proc/self/exe", argv);
}

}  // namespace

int main(int argc, char** argv) {
  bound_openmp_spinning(argv);
  CLI::App app{
      "mufric — a friction service for machining simulation.\n"
      "Answers mu(contact pressure, sliding velocity, temperature) with a confidence interval from a\n"
      "Gaussian-process surrogate or an empirical law, learned from a high-fidelity micro-model of the\n"
      "contact zone (`mufric micro`). Quantities carry units: 800MPa, 100m/min, 500C."};
  app.set_version_flag("--version", mufric::code_version());
  app.require_subcommand(1);
  mufric::app::add_surrogate_commands(app);
  mufric::app::add_bench_command(app);
  mufric::app::add_service_commands(app);
  mufric::app::add_micro_commands(app);
  mufric::app::add_dataset_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const mufric::Error& e) {
    std::fprintf(stderr, "mufric: error: %s\n", e.what());
    return 2;
  } catch (const H5::Exception& e) {
    std::fprintf(stderr, "mufric: error: HDF5: %s\n", e.getDetailMsg().c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mufric: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
