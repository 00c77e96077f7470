#pragma once
// Held-out accuracy of a model on a dataset: relative errors and interval coverage.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "common/dataset_file.hpp"
#include "surrogate/core/friction_model.hpp"

namespace mufric {

struct AccuracyReport {
  long long points = 0;
  long long extrapolated = 0;         // test points outside the model's training box
  double mean_relative_error = 0.0;   // |μ̂ − μ| / max(|μ|, floor)
  double max_relative_error = 0.0;
  double rmse = 0.0;
  double coverage = 0.0;              // fraction of test μ inside the interval at `level`
  double level = 0.95;
  double seconds_per_point = 0.0;     // mean+CI evaluation time
};

// |error| relative to |reference|, with the reference floored so that μ = 0 gives a finite figure.
inline double relative_error(double error, double reference) {
  constexpr double kRelativeErrorFloor = 1e-12;
  return std::abs(error) / std::max(std::abs(reference), kRelativeErrorFloor);
}

// Inputs are matched by name, so a test file may order its columns differently; a missing input
// throws Error naming it.
AccuracyReport held_out_accuracy(const FrictionModel& model, const TrainingSet& test, double level);

// Reorders the columns of `x` (declared by `from`) into the model's input order.
QueryBatch align_inputs(const Eigen::MatrixXd& x, const InputSpace& from, const InputSpace& to, const std::string& where);

struct SamplingOptions {
  long long samples = 200;
  std::uint64_t seed = 1;
  double noise_std = 0.0;  // additive Gaussian noise on μ (absolute), to mimic measurement scatter
};

// A dataset drawn from a model: Latin-hypercube points in the model's box (McKay, Beckman & Conover
// 1979), μ from the model, plus optional noise. For building a GP from an empirical law and for tests.
Dataset sample_model(const FrictionModel& model, const SamplingOptions& options, const std::string& source);

}  // namespace mufric
