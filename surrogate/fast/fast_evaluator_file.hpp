#pragma once
// A fast evaluator's storage in a model file (a GP's and a calibrated model's, under their groups):
// its grid, node values and bounds with a checksum, refused at load unless the checksum matches and
// sampled nodes are the exact model's.
#include <memory>
#include <string>

#include "common/h5_file.hpp"
#include "surrogate/fast/fast_evaluator.hpp"
#include "surrogate/core/friction_model.hpp"

namespace mufric {

void write_fast_evaluator(h5::Writer& out, const FastEvaluator& fast, const std::string& group);
// `model` is the exact model the grid tabulates (its nodes are spot-checked against it).
std::shared_ptr<const FastEvaluator> read_fast_evaluator(const h5::Reader& in, const FrictionModel& model, const std::string& group);

}  // namespace mufric
