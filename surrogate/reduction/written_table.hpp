#pragma once
#include <string>

namespace mufric {

// A table a reduction writes, as text: its file name (relative to the output folder) and content.
struct WrittenTable {
  std::string file_name, text;
};

}  // namespace mufric
