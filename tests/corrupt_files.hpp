#pragma once
// Corruptions of HDF5 files as a flipped bit or a bad copy makes them, for regression tests.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace mufric::test {

// Flips the second byte of the length of the first object in the file's first global heap
// collection (HDF5 file format spec. III.E: "GCOL", version, 3 reserved, 8-byte collection size,
// then objects: 2-byte index, 2-byte reference count, 4 reserved, 8-byte size). In a mufric file
// that object is a variable-length string attribute (the root 'format'); Debian's HDF5 1.10
// dereferences past the heap reading it and dies of SIGSEGV.
inline void flip_global_heap_string_length(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream content;
  content << in.rdbuf();
  in.close();
  const std::string text = content.str();
  std::vector<char> bytes(text.begin(), text.end());
  const std::string signature = "GCOL";
  const auto at = std::search(bytes.begin(), bytes.end(), signature.begin(), signature.end());
  if (at == bytes.end()) throw std::runtime_error(path + ": no global heap collection");
  const auto first_object = static_cast<size_t>(at - bytes.begin()) + 16;
  const size_t size_field = first_object + 8;
  if (size_field + 8 > bytes.size()) throw std::runtime_error(path + ": global heap truncated");
  bytes[size_field + 1] = static_cast<char>(bytes[size_field + 1] ^ 0xff);
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace mufric::test
