#include "surrogate/gp/gp_training_data.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"

namespace mufric {
namespace {

// Outputs whose population std is below this fraction of |mean| are treated as constant.
constexpr double kConstantOutputRelative = 1e-12;

}  // namespace

// Checks the data, normalises them into `state` (training points, mean and scale) and sets the noise
// model: the samples' own standard errors as the shared scatter or on the diagonal, as asked.
NormalisedData prepare_training_data(const TrainingSet& data, const GpTrainingOptions& options,
                                     GaussianProcess::State& state, GpTrainingReport& report) {
  const Eigen::Index n = data.x.rows();
  const auto d = static_cast<Eigen::Index>(data.inputs.size());
  if (n == 0) throw Error("training set is empty");
  if (data.x.cols() != d) throw Error("training inputs have " + std::to_string(data.x.cols()) + " columns for " +
                                      std::to_string(d) + " declared inputs");
  if (!data.x.allFinite() || !data.mu.allFinite()) throw Error("training data contain non-finite values");
  for (const auto& input : data.inputs) {
    if (!(input.lo < input.hi)) {
      throw Error("input '" + input.name + "' has an empty box [" + std::to_string(input.lo) + ", " +
                  std::to_string(input.hi) + "]; it cannot be scaled (is it constant in the data?)");
    }
  }
  state.inputs = data.inputs;
  state.x_train = data.x;
  state.y_train = data.mu;
  state.y_mean = data.mu.mean();
  const double y_std = std::sqrt((data.mu.array() - state.y_mean).square().mean());
  if (!(y_std > kConstantOutputRelative * std::abs(state.y_mean)) || y_std == 0.0) {
    state.y_scale = 1.0;
    report.warnings.push_back("outputs are constant (μ = " + std::to_string(state.y_mean) +
                              "): the model predicts that value with a near-zero interval");
  } else {
    state.y_scale = y_std;
  }
  NormalisedData normalised{to_unit_box(data.x, data.inputs), (data.mu.array() - state.y_mean) / state.y_scale};
  // The samples' own standard errors: their RMS widens the served interval; on request, each one's
  // variance also goes on the diagonal.
  const bool all_std = data.mu_std.size() == n && data.mu_std.allFinite();
  state.interval_of_mean = options.interval_of_mean;
  if (options.interval_of_mean) {
    if (!options.sample_noise && !options.noise_term) {
      throw Error("an interval of the mean needs the samples' own variances on the diagonal or a learned noise term");
    }
  } else if (all_std) {
    state.micro_std_error = std::sqrt(data.mu_std.array().square().mean());
    report.micro_std_error = state.micro_std_error;
  } else if (data.mu_std.size() == n && data.mu_std.array().isFinite().any()) {
    report.warnings.push_back("only some samples carry a standard error of mu: the micro-model's scatter is left out of "
                              "the interval");
  }
  if (options.sample_noise) {
    if (!all_std) throw Error("--sample-noise: every training sample needs its standard error of mu (/samples/mu_std)");
    state.known_noise = (data.mu_std.array() / state.y_scale).square().matrix();
    report.sample_noise_used = true;
  }
  return normalised;
}


}  // namespace mufric
