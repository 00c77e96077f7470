#include "surrogate/calibration/coefficient_evidence.hpp"

#include <cmath>

#include "common/units.hpp"
#include "common/wording.hpp"

namespace mufric {
namespace {

// A prior's SD within [lo, hi] (the box cuts it), by the trapezoid rule on its density.
double prior_sd_within(const Prior& prior, double lo, double hi) {
  constexpr int kIntervals = 2000;
  double mass = 0.0, first = 0.0, second = 0.0;
  for (int k = 0; k <= kIntervals; ++k) {
    const double x = lo + (hi - lo) * k / kIntervals;
    const double log_density = prior.log_density(x);
    const double weight = (k == 0 || k == kIntervals ? 0.5 : 1.0) * (std::isfinite(log_density) ? std::exp(log_density) : 0.0);
    mass += weight, first += weight * x, second += weight * x * x;
  }
  if (!(mass > 0.0)) return 0.0;
  const double mean = first / mass;
  return std::sqrt(std::max(0.0, second / mass - mean * mean));
}

std::string verdict(const CoefficientEvidence& e, const std::vector<CoefficientEvidence>& all) {
  if (e.determination != Determination::determined && e.partner >= 0) return "only with " + all[static_cast<size_t>(e.partner)].name;
  switch (e.determination) {
    case Determination::determined: return "determined";
    case Determination::weakly_determined: return "weakly determined";
    case Determination::not_determined: return "not determined";
  }
  return "";
}

}  // namespace

std::vector<CoefficientEvidence> coefficient_evidence(const CalibrationProblem& problem, const CalibrationResult& result) {
  const Eigen::Index n = std::min<Eigen::Index>(problem.parameter_count(), static_cast<Eigen::Index>(result.summary.size()));
  std::vector<CoefficientEvidence> out;
  // Pearson correlations of the coefficients' pooled samples.
  Eigen::MatrixXd correlation = Eigen::MatrixXd::Identity(n, n);
  if (result.samples.rows() > 1 && result.samples.cols() >= n) {
    const Eigen::MatrixXd centred = result.samples.leftCols(n).rowwise() - result.samples.leftCols(n).colwise().mean();
    const Eigen::MatrixXd covariance = centred.transpose() * centred / static_cast<double>(result.samples.rows() - 1);
    for (Eigen::Index a = 0; a < n; ++a)
      for (Eigen::Index b = 0; b < n; ++b) {
        const double scale = std::sqrt(covariance(a, a) * covariance(b, b));
        correlation(a, b) = scale > 0.0 ? covariance(a, b) / scale : (a == b ? 1.0 : 0.0);
      }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    CoefficientEvidence e;
    e.name = problem.parameters()[static_cast<size_t>(j)];
    const InputSpec& input = input_of(problem.emulator(), e.name);
    e.prior_sd = prior_sd_within(problem.prior_of(j), input.lo, input.hi);
    e.posterior_sd = result.summary[static_cast<size_t>(j)].sd;
    e.share = e.prior_sd > 0.0 ? e.posterior_sd / e.prior_sd : 0.0;
    e.determination = e.share > kUninformedPosteriorShare      ? Determination::not_determined
                      : e.share > kWeaklyInformedPosteriorShare ? Determination::weakly_determined
                                                                : Determination::determined;
    for (Eigen::Index k = 0; k < n; ++k) {
      e.correlations.push_back(correlation(j, k));
      if (k != j && std::abs(correlation(j, k)) >= kCombinedCorrelation &&
          (e.partner < 0 || std::abs(correlation(j, k)) > std::abs(e.correlations[static_cast<size_t>(e.partner)])))
        e.partner = static_cast<int>(k);
    }
    out.push_back(std::move(e));
  }
  return out;
}

std::string describe_evidence(const CalibrationProblem& problem, const std::vector<CoefficientEvidence>& evidence) {
  if (evidence.empty()) return {};
  std::string text = "what the measurements determine (each coefficient's posterior SD against its prior's within the model's box";
  text += evidence.size() > 1 ? "; its correlation with the others in the posterior):\n" : "):\n";
  text += text_printf("  %-28s %12s %12s %8s  %-30s", "coefficient", "prior sd", "posterior sd", "share", "verdict");
  if (evidence.size() > 1)
    for (const auto& e : evidence) text += text_printf(" %12.12s", e.name.c_str());
  text += "\n";
  for (size_t j = 0; j < evidence.size(); ++j) {
    const auto& e = evidence[j];
    const QuantityKind kind = problem.coordinate_kind(static_cast<Eigen::Index>(j));
    text += text_printf("  %-28s %12s %12s %7.0f %%  %-30s", e.name.c_str(), format_human_difference(e.prior_sd, kind).c_str(),
                        format_human_difference(e.posterior_sd, kind).c_str(), 100.0 * e.share, verdict(e, evidence).c_str());
    if (evidence.size() > 1)
      for (double c : e.correlations) text += text_printf(" %12.2f", c);
    text += "\n";
  }
  text += text_printf("  (share: posterior SD over prior SD; over %.0f %% the posterior is essentially the prior, over %.0f %% the "
                      "data narrow it little; a correlation of magnitude %.1f or more: the data fix a combination of the two)\n",
                      100.0 * kUninformedPosteriorShare, 100.0 * kWeaklyInformedPosteriorShare, kCombinedCorrelation);
  return text;
}

std::vector<std::string> evidence_warnings(const CalibrationProblem& problem, const std::vector<CoefficientEvidence>& evidence) {
  std::vector<std::string> warnings;
  for (size_t j = 0; j < evidence.size(); ++j) {
    const auto& e = evidence[j];
    // One seen only with a partner is the pair's warning below.
    if (e.determination == Determination::not_determined && e.partner < 0) {
      const InputSpec& input = input_of(problem.emulator(), e.name);
      warnings.push_back(e.name + ": its posterior SD is " + text_printf("%.0f %%", 100.0 * e.share) + " of its prior's (" +
                         problem.prior_of(static_cast<Eigen::Index>(j)).describe(input.kind()) +
                         " within the box): the measurements hardly inform it, the result is mostly the prior");
    }
    for (size_t k = j + 1; k < evidence.size(); ++k) {
      if (std::abs(e.correlations[k]) < kCombinedCorrelation) continue;
      warnings.push_back(e.name + " and " + evidence[k].name + text_printf(": correlation %+.2f in the posterior", e.correlations[k]) +
                         ": the measurements determine a combination of the two (" +
                         (e.correlations[k] > 0 ? "raising one is made up by raising the other" : "raising one is made up by lowering the other") +
                         ") more than either alone; fix one (--fix) or measure where they act differently");
    }
  }
  return warnings;
}

}  // namespace mufric
