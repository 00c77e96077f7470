// measurements: a pair's measured tests turned into the rows `mufric calibrate` reads.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "app/commands.hpp"
#include "common/files.hpp"
#include "surrogate/reduction/orthogonal_cut_files.hpp"
#include "surrogate/reduction/tribometer.hpp"

namespace mufric::app {
namespace {

void write_tables(const std::filesystem::path& folder, const std::vector<WrittenTable>& tables) {
  if (!folder.empty()) std::filesystem::create_directories(folder);
  for (const auto& table : tables) {
    const std::string path = (folder / table.file_name).string();
    write_file_atomically(path, table.text);
    std::printf("wrote %s\n", path.c_str());
  }
}

std::filesystem::path output_folder(const std::string& setup, const std::string& out_dir) {
  return out_dir.empty() ? std::filesystem::path(setup).parent_path() : std::filesystem::path(out_dir);
}

// What every reduction takes: its setup and where the tables go, and the Monte Carlo's draws and
// seed over the setup's.
struct ReductionOptions {
  std::string setup, out_dir;
  int draws = 0;
  long long seed = -1;
};

std::shared_ptr<ReductionOptions> add_reduction_options(CLI::App* command, const std::string& setup_help) {
  auto options = std::make_shared<ReductionOptions>();
  command->add_option("setup", options->setup, setup_help)->required()->check(CLI::ExistingFile);
  command->add_option("--out-dir", options->out_dir, "where the tables go (default: the setup's folder)");
  command->add_option("--draws", options->draws, "Monte Carlo draws (default: the setup's, or 20000)")->check(CLI::Range(2, 100000000));
  command->add_option("--seed", options->seed, "the draws' seed, as numpy.random.default_rng(seed) (default: the setup's, or 2026)")
      ->check(CLI::Range(0LL, 4294967295LL));
  return options;
}

// The setup's draws and seed, or the command line's where given.
template <typename Setup>
void apply_overrides(const ReductionOptions& options, Setup& setup) {
  if (options.draws > 0) setup.draws = options.draws;
  if (options.seed >= 0) setup.seed = static_cast<std::uint32_t>(options.seed);
}

}  // namespace

void add_measurements_command(CLI::App& app) {
  auto* measurements = app.add_subcommand("measurements", "A pair's measured tests turned into the rows calibrate reads");
  measurements->require_subcommand(1);
  auto* orthogonal = measurements->add_subcommand(
      "orthogonal",
      "Orthogonal cutting tests (forces per speed and uncut chip thickness, chip ratio) to the rake face: mu, normal stress, "
      "sliding velocity and interface temperature per speed, with their SDs by Monte Carlo (edge forces apart by the "
      "forces' lines in h, Merchant's friction, Oxley's contact length and temperature). Writes the analysis table and the "
      "calibration rows beside the setup (or in --out-dir) and prints one line per speed");
  const auto options = add_reduction_options(orthogonal, "the setup (JSON): the tests' CSV, their columns, the tool's rake, the cut's "
                                                         "width, the work material's density and thermal ranges (docs/new-pair.md)");
  orthogonal->callback([options] {
    OrthogonalCutStudy study = read_orthogonal_cut_study(options->setup);
    apply_overrides(*options, study.setup);
    const auto results = rake_face_from_orthogonal_cuts(study.cuts, study.setup);
    std::fputs(orthogonal_cut_summary(study, results).c_str(), stdout);
    write_tables(output_folder(options->setup, options->out_dir), orthogonal_cut_tables(study, results));
  });

  auto* tribometer = measurements->add_subcommand(
      "tribometer",
      "Pin-on-disc or open-tribometer tests (apparent mu against sliding velocity and normal force, a spherical pin) to "
      "the interface's mu: the pin's ploughing taken out (Goddard & Wilman's sphere ploughing a plastic surface at the "
      "work's flow pressure) or kept and stated (\"ploughing\": \"none\"), with SDs by Monte Carlo. Writes the analysis "
      "table and the calibration rows beside the setup (or in --out-dir) and prints one line per test");
  const auto tribometer_options = add_reduction_options(tribometer, "the setup (JSON): the tests' CSV, their columns, the pin's radius, "
                                                                    "the work's flow pressure, the ploughing correction (docs/new-pair.md)");
  tribometer->callback([options = tribometer_options] {
    TribometerStudy study = read_tribometer_study(options->setup);
    apply_overrides(*options, study.setup);
    const auto results = friction_from_tribometer(study.tests, study.setup);
    std::fputs(tribometer_summary(study, results).c_str(), stdout);
    write_tables(output_folder(options->setup, options->out_dir), tribometer_tables(study, results));
  });
}

}  // namespace mufric::app
