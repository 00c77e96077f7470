#pragma once
// Shared by the libFuzzer targets: the input bytes as a file (the loaders read paths), and the rule
// every target checks — a bad input may only end in mufric::Error.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>

namespace mufric::fuzz {

// One file per process, rewritten for every input (in /dev/shm when present: no disk traffic).
inline const std::string& input_path(const char* extension) {
  static const std::string path = std::string(::access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp") +
                                  "/mufric-fuzz-" + std::to_string(::getpid()) + extension;
  return path;
}

inline const std::string& write_input(const uint8_t* data, size_t size, const char* extension) {
  const std::string& path = input_path(extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                 static_cast<std::streamsize>(size));
  return path;
}

}  // namespace mufric::fuzz
