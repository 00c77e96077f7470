#pragma once
#include <optional>
#include <string>

namespace mufric {
// The whole content of a file, or nothing if it cannot be opened (the caller names it in its error).
std::optional<std::string> read_whole_file(const std::string& path);
// Writes `text` to a temporary file beside `path` and renames it over `path`: a crash never leaves
// half a file. Throws Error naming the path.
void write_file_atomically(const std::string& path, const std::string& text);
// Hex SHA-256 (OpenSSL) of bytes, and of a file's bytes (Error naming the path if it cannot be read).
std::string sha256_hex(const std::string& bytes);
std::string sha256_file(const std::string& path);
}  // namespace mufric
