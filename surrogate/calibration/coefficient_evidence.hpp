#pragma once
// What the measurements determine of each calibrated coefficient: how far its posterior narrowed its
// prior (SDs within the model's box) and how it is correlated with the others in the posterior, with
// a verdict in words. A coefficient the data cannot see keeps its prior; two the data see only
// together (μ at the measured states fixes a curve in their plane) are strongly correlated.
#include <string>
#include <vector>

#include "surrogate/calibration/calibration.hpp"

namespace mufric {

// Posterior SD over prior SD (within the box) above which a coefficient is not determined by the
// data (the posterior is essentially the prior), and above which it is only weakly determined.
inline constexpr double kUninformedPosteriorShare = 0.8;
inline constexpr double kWeaklyInformedPosteriorShare = 0.5;
// Two coefficients whose posterior correlation is at least this (in magnitude) are determined as a
// combination more than each alone.
inline constexpr double kCombinedCorrelation = 0.8;

enum class Determination { determined, weakly_determined, not_determined };

struct CoefficientEvidence {
  std::string name;
  double prior_sd = 0.0, posterior_sd = 0.0;  // SI, the prior's within the model's box
  double share = 0.0;                         // posterior_sd / prior_sd
  Determination determination = Determination::determined;
  std::vector<double> correlations;           // with each calibrated coefficient, in the problem's order
  // The coefficient it is most strongly correlated with, if at least kCombinedCorrelation: the data
  // determine the two's combination (an index into the evidence; −1: none).
  int partner = -1;
};

// Per calibrated coefficient, in the problem's order.
std::vector<CoefficientEvidence> coefficient_evidence(const CalibrationProblem& problem, const CalibrationResult& result);

// The table and its verdicts, for calibrate's report.
std::string describe_evidence(const CalibrationProblem& problem, const std::vector<CoefficientEvidence>& evidence);

// One warning per coefficient not determined and per strongly correlated pair (the caller prints them).
std::vector<std::string> evidence_warnings(const CalibrationProblem& problem, const std::vector<CoefficientEvidence>& evidence);

}  // namespace mufric
