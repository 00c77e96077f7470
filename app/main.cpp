// mufric: friction coefficient μ(p, v, T) with a confidence interval, for meso-scale machining codes.
#include <CLI/CLI.hpp>
#include <H5Cpp.h>

#include <cstdio>
#include <exception>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "common/version.hpp"

int main(int argc, char** argv) {
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
