#pragma once
// The training data as the fit sees them (surrogate/gp/gp_training.cpp): checked, normalised into
// the GP's state, and the noise model set from the samples' own standard errors.
#include <Eigen/Dense>

#include "surrogate/gp/gp_training.hpp"

namespace mufric {

// The training data normalised: unit-box inputs, outputs (μ − mean)/scale.
struct NormalisedData {
  Eigen::MatrixXd x_unit;
  Eigen::VectorXd y;
};

// Checks the data, normalises them into `state` (training points, mean and scale) and sets the noise
// model: the samples' own standard errors as the shared scatter or on the diagonal, as asked.
NormalisedData prepare_training_data(const TrainingSet& data, const GpTrainingOptions& options,
                                     GaussianProcess::State& state, GpTrainingReport& report);

}  // namespace mufric
