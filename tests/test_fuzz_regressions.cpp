// Every input the fuzzers (tests/fuzz) found to crash, hang or abort is kept in
// tests/fuzz/regressions/<target>/ and replayed here. "ours-*" faulted in mufric's own code and must
// now be an Error in-process; "hdf5-*" faults inside libhdf5 itself (a hang or a wild pointer there)
// and must be an Error through the isolated loaders that the CLI and the server use.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric {
namespace {

namespace fs = std::filesystem;

// A hang in libhdf5 is cut after this long (the CLI and server default is 60 s).
constexpr double kReplaySeconds = 5.0;

std::vector<fs::path> regressions(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(MUFRIC_SOURCE_DIR) / "tests/fuzz/regressions" / target)) {
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

bool ours(const fs::path& file) { return file.filename().string().rfind("ours-", 0) == 0; }

// Replays every kept input of `target`: in-process for mufric's own faults, isolated for libhdf5's.
template <class InProcess, class Isolated>
void replay(const std::string& target, InProcess in_process, Isolated isolated) {
  const auto files = regressions(target);
  ASSERT_FALSE(files.empty());
  IsolationLimits limits;
  limits.seconds = kReplaySeconds;
  for (const auto& file : files) {
    EXPECT_THROW(ours(file) ? (void)in_process(file.string()) : (void)isolated(file.string(), limits), Error) << file;
  }
}

TEST(FuzzRegressions, DatasetFiles) {
  replay("fuzz_dataset_file", [](const std::string& f) { return read_dataset(f); },
         [](const std::string& f, const IsolationLimits& l) { return read_dataset_isolated(f, l); });
}

TEST(FuzzRegressions, ModelFiles) {
  replay("fuzz_model_file", [](const std::string& f) { return load_model(f); },
         [](const std::string& f, const IsolationLimits& l) { return load_model_isolated(f, l); });
}

}  // namespace
}  // namespace mufric
