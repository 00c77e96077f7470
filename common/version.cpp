#include "common/version.hpp"

#include <ctime>

#include "mufric_code_version.hpp"  // generated at build time: MUFRIC_CODE_VERSION

namespace mufric {

const std::string& code_version() {
  static const std::string version = MUFRIC_CODE_VERSION;
  return version;
}

std::string utc_timestamp() {
  std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace mufric
