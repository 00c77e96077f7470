#pragma once
// Diagnostic switches from the environment (MUFRIC_TRACE_NEWTON, MUFRIC_TRACE_COUPLING, …).
#include <cstdlib>

namespace mufric {

// true when the variable is set and neither empty nor starting with '0'.
inline bool environment_flag(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && *v != '0';
}

}  // namespace mufric
