#pragma once
// A path for a test's scratch file: under the system's temporary directory, in a folder of this
// process's own (created on first use), so that tests running side by side (ctest -j) never share one.
#include <unistd.h>

#include <filesystem>
#include <string>

namespace mufric::test {

inline std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("mufric_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

}  // namespace mufric::test
