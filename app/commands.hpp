#pragma once
#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

namespace mufric::app {

// A real-valued option within [lo, hi]. Not CLI::Range: "nan" and "inf" parse as doubles, and NaN
// passes Range's comparisons (each one is false), so `--poll nan` reached the server loop. The
// message has Range's form, after the option's name.
inline CLI::Validator FiniteRange(double lo, double hi) {
  const std::string range = "[" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) return "Value " + text + " is not a finite number";
        if (value < lo || value > hi) return "Value " + text + " not in range " + range;
        return {};
      },
      "FLOAT in " + range);
}

// Each adds its subcommand(s) to the application; the callbacks print and may throw mufric::Error.
void add_surrogate_commands(CLI::App& app);
// eval and predict, which add_surrogate_commands wires.
void add_predict_commands(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);
// measurements orthogonal: measured tests turned into calibration rows.
void add_measurements_command(CLI::App& app);
void add_service_commands(CLI::App& app);
void add_micro_commands(CLI::App& app);
// plan / run / refine / status / merge under the `dataset` subcommand that add_surrogate_commands
// creates (which adds `dataset from-model` itself).
void add_dataset_commands(CLI::App& app);
// init / run / status / rollback of the on-line learner.
void add_learn_command(CLI::App& app);
}  // namespace mufric::app
