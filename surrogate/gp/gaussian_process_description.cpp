#include "surrogate/gp/gaussian_process.hpp"

#include <cmath>
#include <sstream>

#include "surrogate/fast/fast_evaluator.hpp"

// What a Gaussian process says about itself: its interval's meaning, its description for `describe`
// and the served Describe reply, and its summary text.
namespace mufric {

std::string_view to_string(IntervalMeaning m) {
  switch (m) {
    case IntervalMeaning::new_run: return "new-run";
    case IntervalMeaning::shared_scatter: return "shared-scatter";
    case IntervalMeaning::mean_over_draws: return "mean-over-draws";
  }
  return "?";
}

std::string gp_interval_meaning(IntervalMeaning m) {
  switch (m) {
    case IntervalMeaning::mean_over_draws:
      return "std = sqrt(model variance): where the micro-model's mu averaged over all draws (tool and chip "
             "surfaces) of the training scene's roughness statistics is expected; stochastic kriging of independent "
             "draws, so it shrinks as the campaign grows. How much one contact patch's mu scatters about it is the "
             "separate patch_std";
    case IntervalMeaning::shared_scatter:
      return "std = sqrt(model variance + learned noise + micro-model scatter): where the micro-model's mu, averaged "
             "over all tools of the training scene's roughness statistics, is expected; the model part shrinks with "
             "more training data, the scatter part (the RMS standard error of the training samples, whose draws every "
             "sample shared) does not: only a dataset of independent draws (dataset plan's default) narrows it";
    case IntervalMeaning::new_run: break;
  }
  return "std = sqrt(model variance + learned noise): where a new micro-model run of the training scene is "
         "expected (the training data carry no standard errors of their own)";
}


KindDescription GaussianProcess::kind_description() const {
  const auto& t = state_.summary;
  return {.training = TrainingDescription{.training_points = static_cast<long long>(state_.x_train.rows()),
                             .loo_mean_relative_error = t.loo_mean_relative_error,
                             .loo_max_relative_error = t.loo_max_relative_error,
                             .loo_coverage_95 = t.loo_coverage_95,
                             .interval = std::string(to_string(interval_meaning())),
                             .interval_meaning = gp_interval_meaning(interval_meaning()),
                             .micro_std_error = state_.micro_std_error},
          .calibration = std::nullopt};
}

std::string leave_one_out_text(const GpTrainingSummary& t, bool noisy_samples) {
  std::ostringstream s;
  s.precision(4);
  s << "leave-one-out (each sample predicted from the others, closed form): ";
  if (t.loo_standardised_rms >= 0.0) {
    s << "standardised residuals RMS " << t.loo_standardised_rms << " (1: the interval is as wide as the errors), ";
  } else {
    s << "standardised residuals not stored in this file (`mufric upgrade --rebuild` adds them), ";
  }
  s << "95 % coverage " << 100.0 * t.loo_coverage_95 << " %; mean relative error " << 100.0 * t.loo_mean_relative_error
    << " %, max " << 100.0 * t.loo_max_relative_error << " %, RMSE " << t.loo_rmse;
  if (noisy_samples) {
    s << ". Each sample is a noisy mean of its own draws, and these errors are mostly that noise, not the "
         "model's error: the residuals and coverage say whether the interval accounts for it; the error "
         "against held-out means of many draws is measured in bench/studies/served_interval/README.md";
  }
  return s.str();
}

std::string GaussianProcess::summary() const {
  std::ostringstream s;
  const auto& h = state_.hyper;
  s << "Gaussian process, RBF-ARD kernel, " << state_.x_train.rows() << " training points\n";
  s << "  signal variance " << h.signal_variance << ", learned noise variance " << (h.noise_term ? h.noise_variance : 0.0)
    << (h.noise_term ? "" : " (no noise term)") << ", jitter " << state_.jitter << "\n";
  if (state_.known_noise.size() != 0) {
    s << "  known per-sample noise (micro-model standard errors): mean variance " << state_.known_noise.mean()
      << ", max " << state_.known_noise.maxCoeff() << " (normalised); RMS standard error of a sample's mu "
      << std::sqrt(state_.known_noise.mean()) * state_.y_scale
      << (state_.micro_std_error > 0.0 ? ", added to every interval as the shared scatter" : "") << "\n";
  }
  s << "  interval: " << gp_interval_meaning(interval_meaning()) << "\n";
  s << "  constant mean " << state_.y_mean
    << (state_.mean_estimated ? ": estimated by generalised least squares, its variance part of the interval (ordinary kriging)"
                              : ": the samples' average, taken as known (simple kriging)")
    << "\n";
  if (patch_scatter_) {
    const auto& p = patch_scatter_->state();
    s << "  patch scatter: a GP of the log per-draw variance of mu on " << p.x_train.rows()
      << " samples; per-draw std from the samples' own draws " << std::exp(0.5 * p.y_train.minCoeff()) << " .. "
      << std::exp(0.5 * p.y_train.maxCoeff()) << " (bias-corrected logs), length scales";
    for (Eigen::Index j = 0; j < p.hyper.length_scales.size(); ++j) s << " " << p.hyper.length_scales(j);
    if (const FastEvaluator* f = patch_scatter_->fast_evaluator()) {
      s << "; fast evaluator of its log variance within " << f->bounds().mu_absolute << " (patch_std within "
        << 0.5 * f->bounds().mu_absolute << " relative)";
    } else {
      s << "; no fast evaluator (the exact scatter GP answers)";
    }
    s << "\n";
  }
  for (size_t j = 0; j < state_.inputs.size(); ++j) {
    s << "  length scale " << state_.inputs[j].name << ": " << h.length_scales(static_cast<Eigen::Index>(j))
      << " (box widths)\n";
  }
  const auto& t = state_.summary;
  s << (state_.mean_estimated ? "  log restricted likelihood (REML) " : "  log marginal likelihood ") << t.log_marginal_likelihood
    << "\n";
  if (!t.dataset_description.empty()) s << "  trained on: " << t.dataset_description << "\n";
  s << "  " << leave_one_out_text(t, state_.known_noise.size() != 0);
  if (fast_) {
    s << "\n  fast evaluator: grid ";
    for (size_t k = 0; k < fast_->grid().cells().size(); ++k) s << (k ? "x" : "") << fast_->grid().cells()[k];
    s << " cells (" << static_cast<double>(fast_->grid().bytes()) / 1e6 << " MB); measured bound: mu "
      << fast_->bounds().mu_absolute << " absolute, std " << fast_->bounds().std_relative << " of "
      << (fast_->bounds().std_floor > 0.0 ? "max(std, " + std::to_string(fast_->bounds().std_floor) + ")" : std::string("std"))
      << "; it answers requests whose tolerances are at least these, inside the box";
  } else {
    s << "\n  fast evaluator: none (the exact model answers; `mufric upgrade` adds one)";
  }
  return s.str();
}

}  // namespace mufric
