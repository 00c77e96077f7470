#pragma once
#include <string>

namespace mufric {
// "<semver>+<git describe>", recorded in every model and dataset file for provenance.
const std::string& code_version();
// Current UTC time as ISO 8601, for provenance attributes.
std::string utc_timestamp();
}  // namespace mufric
