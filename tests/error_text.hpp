#pragma once
// The message of the mufric::Error a call throws, or "" when it throws none: for tests that check an
// error names its field, file or row.
#include <functional>
#include <string>

#include "common/error.hpp"

namespace mufric::test {

inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace mufric::test
