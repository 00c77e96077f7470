#pragma once
#include <CLI/CLI.hpp>

namespace mufric::app {
// Each adds its subcommand(s) to the application; the callbacks print and may throw mufric::Error.
void add_surrogate_commands(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_service_commands(CLI::App& app);
void add_micro_commands(CLI::App& app);
// plan / run / refine / status / merge under the `dataset` subcommand that add_surrogate_commands
// creates (which adds `dataset from-model` itself).
void add_dataset_commands(CLI::App& app);
}  // namespace mufric::app
