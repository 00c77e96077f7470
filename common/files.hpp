#pragma once
#include <optional>
#include <string>

namespace mufric {
// The whole content of a file, or nothing if it cannot be opened (the caller names it in its error).
std::optional<std::string> read_whole_file(const std::string& path);
}  // namespace mufric
