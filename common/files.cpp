#include "common/files.hpp"

#include <filesystem>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <openssl/sha.h>

#include "common/error.hpp"

namespace mufric {

std::optional<std::string> read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

void write_file_atomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary);
    if (!out) throw Error(path + ": cannot write");
    out << text;
    out.close();
    if (!out) throw Error(path + ": write failed");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw Error(path + ": cannot write (" + error.message() + ")");
}

std::string sha256_hex(const std::string& bytes) {
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), digest);
  std::string hex;
  for (unsigned char byte : digest) {
    char part[3];
    std::snprintf(part, sizeof part, "%02x", byte);
    hex += part;
  }
  return hex;
}

std::string sha256_file(const std::string& path) {
  const auto bytes = read_whole_file(path);
  if (!bytes) throw Error(path + ": cannot open for hashing");
  return sha256_hex(*bytes);
}

void copy_file_atomically(const std::string& from, const std::string& to) {
  const auto bytes = read_whole_file(from);
  if (!bytes) throw Error(from + ": cannot read it to copy it to " + to);
  write_file_atomically(to, *bytes);
}

std::string file_version(const std::string& path) { return sha256_file(path).substr(0, kFileVersionDigits); }

std::string rotated_log_path(const std::string& log_path) { return log_path + ".1"; }

}  // namespace mufric
