#pragma once
// One exception type for every user-facing failure: the message names the file, row or field.
#include <stdexcept>
#include <string>

namespace mufric {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mufric
