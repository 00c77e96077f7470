#pragma once
// What a model's training data were, in one paragraph a reader of `describe` can act on: how the
// samples were made (the scene and code), the plan, the draws, the mesh, how many samples converged
// and what the micro-model time was. train stores it in the model file (/gp/training).
#include <optional>
#include <string>

#include "common/dataset_file.hpp"

namespace mufric {

std::string campaign_summary(const Dataset& d);

// The samples' wall time summed (their "wall_seconds" diagnostic, NaN counted as 0); none when the
// database does not record it or holds no sample.
std::optional<double> total_wall_seconds(const Dataset& d);

}  // namespace mufric
