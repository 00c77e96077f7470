#pragma once
#include <cstddef>
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
// A file's bytes written over `to` by write_file_atomically (Error naming `from` if it cannot be read):
// a reader of `to` sees the old file or the new one, never a part.
void copy_file_atomically(const std::string& from, const std::string& to);
// A model file's version as the server names it (on the wire and in its log) and the learner keeps
// it: the first kFileVersionDigits hex digits of its SHA-256.
inline constexpr std::size_t kFileVersionDigits = 16;
std::string file_version(const std::string& path);
// Where a full log is renamed when a new one begins at `log_path` (serve --log-uncertain writes it,
// the learner reads it): one name for both.
std::string rotated_log_path(const std::string& log_path);
}  // namespace mufric
