// The Gaussian process's kind in model files (/gp): GaussianProcess::write, read and their groups
// (a calibrated model's emulator and a patch scatter are GPs under groups of their own).
#include "surrogate/gp/gaussian_process.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "surrogate/core/cholesky.hpp"
#include "surrogate/fast/fast_evaluator_file.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {
namespace {

// A loaded GP must satisfy K α = y to this normwise backward error; a backward-stable solve gives
// about n·ε, a flipped bit in α, L or x_train gives O(1). Lenient when α is large (ill-conditioned K),
// hence the entry-wise factor check below when the factor is stored.
constexpr double kLoadBackwardErrorTolerance = 1e-8;
// Entries of L Lᵀ must match the kernel rebuilt from x_train and the hyper-parameters to this
// fraction of the diagonal; roundoff of a Cholesky factorisation is about n·ε.
constexpr double kFactorEntryTolerance = 1e-8;
// α recomputed from the stored factor must match the stored α this closely (same algorithm).
constexpr double kAlphaRecomputeTolerance = 1e-10;

// Compares (L Lᵀ)ᵢⱼ with Kᵢⱼ on the sub-diagonal and three full columns: O(n²), and any change of
// a hyper-parameter or a training input moves some of these entries.
bool factor_matches_kernel(const Eigen::MatrixXd& l, const Eigen::MatrixXd& kf, double diagonal) {
  const Eigen::Index n = l.rows();
  const double tolerance = kFactorEntryTolerance * (kf(0, 0) + diagonal);
  auto entry_ok = [&](Eigen::Index i, Eigen::Index j) {  // i ≥ j
    const double llt = l.row(i).head(j + 1).dot(l.row(j).head(j + 1));
    const double k = kf(i, j) + (i == j ? diagonal : 0.0);
    return std::abs(llt - k) <= tolerance;
  };
  for (Eigen::Index i = 1; i < n; ++i) {
    if (!entry_ok(i, i - 1)) return false;
  }
  for (const Eigen::Index j : {Eigen::Index{0}, n / 2, n - 1}) {
    for (Eigen::Index i = j; i < n; ++i) {
      if (!entry_ok(i, j)) return false;
    }
  }
  return true;
}

// The fields of /gp/training, written and read from the same tables so the two cannot drift apart.
constexpr std::pair<const char*, double GpTrainingSummary::*> kSummaryNumbers[] = {
    {"log_marginal_likelihood", &GpTrainingSummary::log_marginal_likelihood},
    {"loo_mean_relative_error", &GpTrainingSummary::loo_mean_relative_error},
    {"loo_max_relative_error", &GpTrainingSummary::loo_max_relative_error},
    {"loo_rmse", &GpTrainingSummary::loo_rmse},
    {"loo_coverage_95", &GpTrainingSummary::loo_coverage_95},
    {"seconds", &GpTrainingSummary::seconds}};
constexpr std::pair<const char*, long long GpTrainingSummary::*> kSummaryCounts[] = {
    {"starts", &GpTrainingSummary::starts}, {"best_start", &GpTrainingSummary::best_start}};
constexpr std::pair<const char*, std::string GpTrainingSummary::*> kSummaryTexts[] = {
    {"dataset_path", &GpTrainingSummary::dataset_path},
    {"dataset_sha256", &GpTrainingSummary::dataset_sha256},
    {"code_version", &GpTrainingSummary::code_version},
    {"created_utc", &GpTrainingSummary::created_utc}};
// Written by every model since it was kept; a file from before has none (read as "").
constexpr const char* kSummaryDatasetDescription = "dataset_description";
// Likewise; a file from before has none, and it is recomputed at load up to this many training points
// (the LOO needs K⁻¹: n³/3, ~0.05 s at 1000).
constexpr const char* kSummaryStandardisedRms = "loo_standardised_rms";
constexpr Eigen::Index kMostPointsForLooAtLoad = 1000;

}  // namespace

void GaussianProcess::write(h5::Writer& out) const { write_group(out, "/gp"); }

void GaussianProcess::write_group(h5::Writer& out, const std::string& group, GridInFile grid) const {
  const auto& s = state_;
  const std::string summary_group = group + "/training", fast_group = group + "/fast_evaluator";
  out.group(group);
  out.string_attribute(group, "kernel", "constant*RBF(ARD)+white; inputs scaled to the unit box, outputs (mu-mean)/scale");
  out.double_attribute(group, "y_mean", s.y_mean);
  out.double_attribute(group, "y_scale", s.y_scale);
  out.double_attribute(group, "signal_variance", s.hyper.signal_variance);
  out.double_attribute(group, "noise_variance", s.hyper.noise_variance);
  out.int_attribute(group, "noise_term", s.hyper.noise_term ? 1 : 0);
  out.double_attribute(group, "jitter", s.jitter);
  out.doubles(group + "/length_scales", s.hyper.length_scales);
  out.matrix(group + "/x_train", s.x_train);
  out.doubles(group + "/y_train", s.y_train);
  out.doubles(group + "/alpha", s.alpha);
  if (s.x_train.rows() <= kStoreCholeskyUpTo) out.matrix(group + "/cholesky_lower", s.cholesky);
  if (s.known_noise.size() != 0) out.doubles(group + "/known_noise", s.known_noise);
  out.double_attribute(group, "micro_std_error", s.micro_std_error);
  out.string_attribute(group, "interval", std::string(to_string(interval_meaning())));
  out.string_attribute(group, "constant_mean", s.mean_estimated ? "estimated" : "average");
  out.group(summary_group);
  for (const auto& [name, field] : kSummaryNumbers) out.double_attribute(summary_group, name, s.summary.*field);
  for (const auto& [name, field] : kSummaryCounts) out.int_attribute(summary_group, name, s.summary.*field);
  for (const auto& [name, field] : kSummaryTexts) out.string_attribute(summary_group, name, s.summary.*field);
  out.string_attribute(summary_group, kSummaryDatasetDescription, s.summary.dataset_description);
  out.double_attribute(summary_group, kSummaryStandardisedRms, s.summary.loo_standardised_rms);
  if (fast_ && grid == GridInFile::with) write_fast_evaluator(out, *fast_, fast_group);
  if (patch_scatter_) patch_scatter_->write_group(out, group + "/patch_scatter");
}

GaussianProcess GaussianProcess::read(const h5::Reader& in, InputSpace inputs) { return read_group(in, std::move(inputs), "/gp"); }

GaussianProcess GaussianProcess::read_group(const h5::Reader& in, InputSpace inputs, const std::string& group) {
  const std::string summary_group = group + "/training", fast_group = group + "/fast_evaluator";
  State s;
  s.inputs = std::move(inputs);
  const auto d = static_cast<Eigen::Index>(s.inputs.size());
  s.x_train = in.matrix(group + "/x_train");
  if (s.x_train.cols() != d) {
    in.fail(group + "/x_train", "has " + std::to_string(s.x_train.cols()) + " columns for " + std::to_string(d) + " inputs");
  }
  const Eigen::Index n = s.x_train.rows();
  if (n == 0) in.fail(group + "/x_train", "no training points");
  if (!s.x_train.allFinite()) in.fail(group + "/x_train", "contains non-finite values");
  s.y_train = in.vector(group + "/y_train", n);
  s.alpha = in.vector(group + "/alpha", n);
  if (!s.alpha.allFinite()) in.fail(group + "/alpha", "contains non-finite values");
  s.y_mean = in.double_attribute(group, "y_mean");
  s.y_scale = in.double_attribute(group, "y_scale");
  s.hyper.signal_variance = in.double_attribute(group, "signal_variance");
  s.hyper.noise_variance = in.double_attribute(group, "noise_variance");
  s.hyper.noise_term = in.int_attribute(group, "noise_term") != 0;
  s.hyper.length_scales = in.vector(group + "/length_scales", d);
  s.jitter = in.double_attribute(group, "jitter");
  if (!(s.hyper.length_scales.array() > 0).all() || !s.hyper.length_scales.allFinite()) {
    in.fail(group + "/length_scales", "must be positive and finite");
  }
  if (!(s.hyper.signal_variance > 0) || !std::isfinite(s.hyper.signal_variance)) {
    in.fail(group, "attribute signal_variance must be positive and finite");
  }
  if (!(s.hyper.noise_variance >= 0) || !std::isfinite(s.hyper.noise_variance)) {
    in.fail(group, "attribute noise_variance must be >= 0 and finite");
  }
  if (!(s.jitter >= 0) || !std::isfinite(s.jitter)) in.fail(group, "attribute jitter must be >= 0 and finite");
  if (!(s.y_scale > 0) || !std::isfinite(s.y_scale)) in.fail(group, "attribute y_scale must be positive and finite");
  if (in.has(group + "/known_noise")) {
    s.known_noise = in.vector(group + "/known_noise", n);
    if (!s.known_noise.allFinite() || !(s.known_noise.array() >= 0).all()) in.fail(group + "/known_noise", "must be finite and >= 0");
  }
  if (in.has_attribute(group, "micro_std_error")) {
    s.micro_std_error = in.double_attribute(group, "micro_std_error");
    if (!(s.micro_std_error >= 0) || !std::isfinite(s.micro_std_error)) {
      in.fail(group, "attribute micro_std_error must be >= 0 and finite");
    }
  }

  // Absent (files before issue 33): new-run or shared-scatter, by micro_std_error.
  if (in.has_attribute(group, "interval")) {
    const std::string meaning = in.string_attribute(group, "interval");
    if (meaning != "new-run" && meaning != "shared-scatter" && meaning != "mean-over-draws") {
      in.fail(group, "attribute interval '" + meaning + "' is not new-run, shared-scatter or mean-over-draws");
    }
    s.interval_of_mean = meaning == "mean-over-draws";
  }

  // Absent (files before the trend term): the average, as known (simple kriging).
  if (in.has_attribute(group, "constant_mean")) {
    const std::string mean = in.string_attribute(group, "constant_mean");
    if (mean != "estimated" && mean != "average") in.fail(group, "attribute constant_mean '" + mean + "' is not estimated or average");
    s.mean_estimated = mean == "estimated";
  }

  Eigen::MatrixXd kf;
  rbf_signal_covariance(to_unit_box(s.x_train, s.inputs), s.hyper, kf);
  // Known per-point noise belongs to the covariance the factor was made of.
  if (s.known_noise.size() != 0) kf.diagonal() += s.known_noise;
  const double diagonal = s.hyper.noise_variance + s.jitter;
  if (in.has(group + "/cholesky_lower")) {
    s.cholesky = in.matrix(group + "/cholesky_lower");
    if (s.cholesky.rows() != n || s.cholesky.cols() != n) in.fail(group + "/cholesky_lower", "is not n × n");
    if (!s.cholesky.allFinite() || !(s.cholesky.diagonal().array() > 0).all()) {
      in.fail(group + "/cholesky_lower", "is not a valid Cholesky factor (non-finite or non-positive diagonal)");
    }
    if (!factor_matches_kernel(s.cholesky, kf, diagonal)) {
      in.fail(group + "/cholesky_lower", "is inconsistent with x_train and the hyper-parameters (L·Lᵀ != K)");
    }
  } else {
    const auto chol = cholesky_with_jitter(kf, diagonal, s.cholesky);
    if (!chol.ok || chol.jitter > 0.0) in.fail(group, "covariance cannot be refactorised with the stored jitter");
  }
  // Consistency, O(n²): α̂ = (L Lᵀ)⁻¹ y from the factor, then K α = y and α = α̂ entry by entry. Every
  // scale below comes from α̂ as well as from α: scaled by ‖α‖ alone, one entry blown up to 1e180 by a
  // flipped exponent bit inflated its own tolerance and passed.
  if (!s.y_train.allFinite()) in.fail(group + "/y_train", "contains non-finite values");
  if (!std::isfinite(s.y_mean)) in.fail(group, "attribute y_mean must be finite");
  const Eigen::VectorXd y = (s.y_train.array() - s.y_mean) / s.y_scale;
  Eigen::VectorXd alpha_from_factor = s.cholesky.triangularView<Eigen::Lower>().solve(y);
  s.cholesky.triangularView<Eigen::Lower>().transpose().solveInPlace(alpha_from_factor);
  const double alpha_size = std::min(s.alpha.lpNorm<Eigen::Infinity>(), alpha_from_factor.lpNorm<Eigen::Infinity>());
  if ((alpha_from_factor - s.alpha).lpNorm<Eigen::Infinity>() > kAlphaRecomputeTolerance * alpha_size) {
    in.fail(group + "/alpha", "is inconsistent with the Cholesky factor and y_train (alpha != K⁻¹y)");
  }
  Eigen::VectorXd k_alpha = kf.selfadjointView<Eigen::Lower>() * s.alpha;
  k_alpha += diagonal * s.alpha;
  const double n_alpha = static_cast<double>(n) * alpha_size;
  const double scale = (kf.lpNorm<Eigen::Infinity>() + diagonal) * n_alpha + y.lpNorm<Eigen::Infinity>();
  if ((k_alpha - y).lpNorm<Eigen::Infinity>() > kLoadBackwardErrorTolerance * scale) {
    in.fail(group + "/alpha", "is inconsistent with x_train, y_train and the hyper-parameters (K·alpha != y)");
  }
  // The generalised-least-squares constant makes the residuals K-orthogonal to it: 1ᵀK⁻¹(y − β̂1) = 1ᵀα = 0.
  if (s.mean_estimated && std::abs(s.alpha.sum()) > kAlphaRecomputeTolerance * n_alpha) {
    in.fail(group, "attribute y_mean is not the estimated constant mean of constant_mean = estimated (sum of alpha != 0)");
  }
  if (in.has(summary_group)) {
    for (const auto& [name, field] : kSummaryNumbers) s.summary.*field = in.double_attribute(summary_group, name);
    for (const auto& [name, field] : kSummaryCounts) s.summary.*field = in.int_attribute(summary_group, name);
    for (const auto& [name, field] : kSummaryTexts) s.summary.*field = in.string_attribute(summary_group, name);
    if (in.has_attribute(summary_group, kSummaryDatasetDescription)) {
      s.summary.dataset_description = in.string_attribute(summary_group, kSummaryDatasetDescription);
    }
    if (in.has_attribute(summary_group, kSummaryStandardisedRms)) {
      s.summary.loo_standardised_rms = in.double_attribute(summary_group, kSummaryStandardisedRms);
    } else if (s.x_train.rows() <= kMostPointsForLooAtLoad) {
      GpTrainingSummary recomputed;
      leave_one_out(s, recomputed);
      s.summary.loo_standardised_rms = recomputed.loo_standardised_rms;
    }
  }
  const InputSpace inputs_of_model = s.inputs;
  GaussianProcess gp(std::move(s));
  if (group.ends_with("/patch_scatter")) gp.set_unbounded_output();  // before its grid's load check
  if (in.has(fast_group)) gp.attach_fast_evaluator(read_fast_evaluator(in, gp, fast_group));
  // Only a model's own GP has a patch scatter (a scatter of the scatter is not a thing, and a file
  // nesting them deeply would recurse here); a calibrated model's emulator is one.
  if (!group.ends_with("/patch_scatter") && in.has(group + "/patch_scatter")) {
    gp.attach_patch_scatter(std::make_shared<const GaussianProcess>(read_group(in, inputs_of_model, group + "/patch_scatter")));
  }
  return gp;
}

}  // namespace mufric
