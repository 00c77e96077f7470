#include "surrogate/gp/stochastic_kriging.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <boost/math/special_functions/digamma.hpp>
#include <boost/math/special_functions/trigamma.hpp>

#include "common/error.hpp"

namespace mufric {
namespace {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// A GP of log s² needs at least two values to learn anything of how it varies.
constexpr int kMinimumScatterSamples = 2;
// Normalised noise variance allowed with one draw per sample: up to ten times μ's variance.
constexpr double kSingleDrawNoiseBound = 10.0;
// Below this many samples the mean's interval is too narrow: the hyper-parameters are plugged in as
// if known, and with a handful of points in three inputs their fit is loose (8 samples x 4 draws
// covered 7 of 10 held-out means, 16 covered 9 of 10: bench/studies/served_interval/README.md, "The trend term").
constexpr Eigen::Index kCalibratedSamples = 16;

void warn_if_too_few_samples(Eigen::Index samples, GpTrainingReport& mean) {
  if (samples >= kCalibratedSamples) return;
  mean.warnings.push_back("only " + std::to_string(samples) + " samples: below " + std::to_string(kCalibratedSamples) +
                          " the interval of the mean is too narrow (its hyper-parameters are taken as known; 8 samples "
                          "covered 7 of 10 held-out means); run more samples before trusting it");
}

}  // namespace

Eigen::VectorXi finite_draws(const TrainingSet& data) {
  Eigen::VectorXi counts = Eigen::VectorXi::Zero(data.x.rows());
  for (Eigen::Index i = 0; i < std::min(data.draw_mu.rows(), counts.size()); ++i) {
    counts(i) = static_cast<int>(data.draw_mu.row(i).array().isFinite().count());
  }
  return counts;
}

DrawVariances draw_variances(const TrainingSet& data) {
  DrawVariances v;
  std::vector<double> logs, variances;
  std::vector<int> counts;
  for (Eigen::Index i = 0; i < data.draw_mu.rows(); ++i) {
    double sum = 0.0;
    int r = 0;
    for (Eigen::Index k = 0; k < data.draw_mu.cols(); ++k) {
      if (!std::isfinite(data.draw_mu(i, k))) continue;
      sum += data.draw_mu(i, k);
      ++r;
    }
    if (r < 2) continue;
    const double mean = sum / r;
    double squares = 0.0;
    for (Eigen::Index k = 0; k < data.draw_mu.cols(); ++k) {
      if (std::isfinite(data.draw_mu(i, k))) squares += (data.draw_mu(i, k) - mean) * (data.draw_mu(i, k) - mean);
    }
    const double s2 = squares / (r - 1);
    if (!(s2 > 0.0)) continue;  // identical draws (a flat tool): no log
    const double k = 0.5 * (r - 1);
    v.rows.push_back(i);
    logs.push_back(std::log(s2) - boost::math::digamma(k) + std::log(k));
    variances.push_back(boost::math::trigamma(k));
    counts.push_back(r);
  }
  const auto m = static_cast<Eigen::Index>(v.rows.size());
  v.log_variance = Eigen::Map<const Eigen::VectorXd>(logs.data(), m);
  v.log_variance_variance = Eigen::Map<const Eigen::VectorXd>(variances.data(), m);
  v.draws = Eigen::Map<const Eigen::VectorXi>(counts.data(), m);
  return v;
}

bool suits_stochastic_kriging(const TrainingSet& data) {
  return data.draws == DrawDesign::independent && data.draw_mu.cols() > 0 && data.draw_mu.rows() == data.x.rows();
}

GaussianProcess train_stochastic_kriging(const TrainingSet& data, const GpTrainingOptions& options,
                                         StochasticKrigingReport* report_out) {
  StochasticKrigingReport report;
  const Eigen::Index n = data.x.rows();
  if (data.draw_mu.rows() != n) throw Error("stochastic kriging: the training set carries no per-draw mu");
  const Eigen::VectorXi draws = finite_draws(data);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (draws(i) == 0) {
      throw Error(data.source_path + ": training sample " + std::to_string(i) + " has no finite per-draw mu (/samples/draw_mu)");
    }
  }
  report.draws = draws.sum();

  // 1. The patch scatter: log s² over the inputs, each value's sampling variance on the diagonal.
  const DrawVariances v = draw_variances(data);
  report.scatter_samples = static_cast<long long>(v.rows.size());
  if (report.scatter_samples < kMinimumScatterSamples) {
    // One draw per sample: the learned noise is the per-draw variance, the same everywhere, and the
    // mean's interval leaves it out (independent draws average it away).
    report.homoscedastic = true;
    GpTrainingOptions mean_options = options;
    mean_options.sample_noise = false;
    mean_options.noise_term = true;
    mean_options.interval_of_mean = true;
    mean_options.estimate_mean = true;
    // Single draws may scatter by more than μ varies over the box: the noise may then exceed the
    // signal, which the default bound (a tenth of μ's variance, for nearly deterministic data) forbids.
    mean_options.bounds.noise_variance_hi = std::max(options.bounds.noise_variance_hi, kSingleDrawNoiseBound);
    TrainingSet mean_data = data;
    mean_data.mu_std.setConstant(std::numeric_limits<double>::quiet_NaN());
    GaussianProcess gp = train_gaussian_process(mean_data, mean_options, &report.mean);
    warn_if_too_few_samples(n, report.mean);
    if (report_out) *report_out = report;
    return gp;
  }
  TrainingSet scatter_data;
  scatter_data.inputs = data.inputs;
  scatter_data.source_path = data.source_path;
  scatter_data.source_hash = data.source_hash;
  scatter_data.x.resize(report.scatter_samples, data.x.cols());
  for (size_t k = 0; k < v.rows.size(); ++k) scatter_data.x.row(static_cast<Eigen::Index>(k)) = data.x.row(v.rows[k]);
  scatter_data.mu = v.log_variance;
  scatter_data.mu_std = v.log_variance_variance.cwiseSqrt();
  GpTrainingOptions scatter_options = options;
  scatter_options.sample_noise = true;
  scatter_options.interval_of_mean = true;
  scatter_options.progress = nullptr;
  auto scatter = std::make_shared<const GaussianProcess>(train_gaussian_process(scatter_data, scatter_options, &report.scatter));

  // 2. The mean: each sample's smoothed variance of its mean, σ²(xᵢ)/rᵢ, on the diagonal.
  const Eigen::VectorXd patch = GaussianProcess::std_from_log_variance(*scatter, data.x);
  TrainingSet mean_data = data;
  mean_data.mu_std = (patch.array().square() / draws.cast<double>().array()).sqrt().matrix();
  GpTrainingOptions mean_options = options;
  mean_options.sample_noise = true;
  mean_options.interval_of_mean = true;
  // The mean level's own uncertainty: with a few samples the signal variance may sit at its lower
  // bound and the interval would otherwise be that of a known constant (bench/studies/calibration/README.md, calibration).
  mean_options.estimate_mean = true;
  GaussianProcess gp = train_gaussian_process(mean_data, mean_options, &report.mean);
  gp.attach_patch_scatter(scatter);
  warn_if_too_few_samples(n, report.mean);
  report.median_patch_std = median(std::vector<double>(patch.data(), patch.data() + n));
  report.median_sample_std_error = median(std::vector<double>(mean_data.mu_std.data(), mean_data.mu_std.data() + n));
  if (report_out) *report_out = report;
  return gp;
}

}  // namespace mufric
