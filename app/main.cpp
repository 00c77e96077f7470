// mufric: friction coefficient μ(p, v, T) with a confidence interval, for meso-scale machining codes.
#include <CLI/CLI.hpp>
#include <H5Cpp.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "common/version.hpp"
#include "common/wording.hpp"

namespace {

// How long an idle OpenMP thread spins before it sleeps (libgomp's default: 300 000 spins when the
// wait policy is unset). On a node shared with another CPU-bound process, a thread spinning at a
// barrier holds the core its descheduled team-mate needs: the default micro run took 2–8× its one-core
// time beside one competing process and 9× beside two. 5000 spins keep the idle-machine speed and
// 1.1× beside one (bench/studies/hardening/README.md, "Threads on a busy machine").
constexpr const char* kOpenMpSpinCount = "5000";

// libgomp reads its wait policy once, when it is loaded, so it must be in the environment before
// the process starts: unless the user chose one, set it and start again (once: the second start
// sees it set). A failed exec leaves everything as it was.
void bound_openmp_spinning(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (::setenv("GOMP_SPINCOUNT", kOpenMpSpinCount, 0) != 0) return;
  ::execv("/proc/self/exe", argv);
}

// The exit code of every error, whether the command line or the work failed (README).
constexpr int kErrorExitCode = 2;

// The subcommands the parser reached ("mufric dataset plan"), for the usage hint of a parse error.
std::string command_line_of(const CLI::App& app) {
  std::string line = "mufric";
  for (const CLI::App* level = &app; !level->get_subcommands().empty();) {
    level = level->get_subcommands().back();
    line += " " + level->get_name();
  }
  return line;
}

// An error message on one line (a few of CLI11's span several).
std::string one_line(std::string message) {
  std::replace(message.begin(), message.end(), '\n', ' ');
  while (!message.empty() && message.back() == ' ') message.pop_back();
  return message;
}

// A suggestion for a mistyped subcommand: the first word of the command line that names no
// subcommand where one is expected, and the nearest name there (at most two edits away).
std::string subcommand_suggestion(const CLI::App& app, int argc, char** argv) {
  constexpr size_t kMostEdits = 2;
  const CLI::App* level = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') continue;
    const auto subcommands = level->get_subcommands([](const CLI::App*) { return true; });
    if (subcommands.empty()) return "";
    const CLI::App* exact = nullptr;
    std::vector<std::string_view> names;
    for (const CLI::App* sub : subcommands) {
      if (sub->get_name() == word) exact = sub;
      names.push_back(sub->get_name());
    }
    if (exact) {
      level = exact;
      continue;
    }
    const std::string_view nearest = mufric::nearest_word(word, names, kMostEdits);
    return nearest.empty() ? "" : "; did you mean `" + std::string(nearest) + "`?";
  }
  return "";
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
  mufric::app::add_calibrate_command(app);
  mufric::app::add_measurements_command(app);
  mufric::app::add_bench_command(app);
  mufric::app::add_service_commands(app);
  mufric::app::add_micro_commands(app);
  mufric::app::add_dataset_commands(app);
  mufric::app::add_learn_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    // A command's own exit code, thrown from its callback (micro run: 3 when the run did not
    // complete); it has said why. CLI11 derives it from ParseError, so it is caught first.
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" with CLI11's success code: their normal output, exit 0.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    // Every other parse error is an error like any other (README: one line, exit code 2), not
    // CLI11's two lines and its own exit codes (105, 106, 114, …).
    std::fprintf(stderr, "mufric: error: %s%s (run `%s --help` for usage)\n", one_line(e.what()).c_str(),
                 subcommand_suggestion(app, argc, argv).c_str(), command_line_of(app).c_str());
    return kErrorExitCode;
  } catch (const mufric::Error& e) {
    std::fprintf(stderr, "mufric: error: %s\n", e.what());
    return kErrorExitCode;
  } catch (const H5::Exception& e) {
    std::fprintf(stderr, "mufric: error: HDF5: %s\n", e.getDetailMsg().c_str());
    return kErrorExitCode;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mufric: error: %s\n", e.what());
    return kErrorExitCode;
  }
  return 0;
}
