#pragma once
// The learner's gate (campaign/learning.hpp, step 5): whether a retrained candidate may replace the
// served version — no worse on what the served version knew, covering its new points, keeping its
// grid certified; for a recalibrated model also covering its measurements. The statistics and the
// verdict's words.
#include <string>

#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/fast/fast_evaluator_build.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// The gate's verdict on a candidate against the served version (gate_candidate).
struct GateDecision {
  bool publish = false;
  std::string reason;               // a sentence: why published, or why kept aside
  long long old_points = 0;         // the served version's training points, found in the candidate's
  double served_loo_rmse = 0.0;     // leave-one-out RMSE at those points: the served version's ...
  double candidate_loo_rmse = 0.0;  // ... and the candidate's (μ units)
  double allowed_loo_rmse = 0.0;    // the most the candidate may reach
  long long new_points = 0;         // the candidate's points the served version had not
  long long new_covered = 0;        // of them inside their leave-one-out 95 % interval
  bool grid_certified = true;       // the candidate's grid meets the tolerances the served one met
  // A calibrated model's: its measurements, and of them inside the candidate's 95 % posterior
  // predictive interval widened by the measurement's own SD.
  long long measurements = 0;
  long long measurements_covered = 0;
  // Kept aside for the round's values (worse on the served version's points, its new points or the
  // measurements not covered), not for its grid or its database: the round's samples are quarantined.
  bool values_refused = false;
};

// Leave-one-out is the held-out error of each version on the served version's own points (R&W eq.
// 5.12): the candidate must reach at most the served one's RMSE plus kGateRmseSlack standard errors of
// an RMS of n terms (RMSE/√(2n), the χ distribution's); its new points must be covered at a rate a
// one-sided binomial test at kGateCoverageSignificance does not reject against 95 %; a served grid
// that met `tolerances` must be met again.
inline constexpr double kGateRmseSlack = 2.0;
inline constexpr double kGateCoverageSignificance = 0.01;
GateDecision gate_candidate(const GaussianProcess& served, const GaussianProcess& candidate,
                            const FastEvaluatorOptions& tolerances);
// A recalibrated model: its emulator gated as a GP is (its grid aside), its measurements covered at a
// rate the same binomial test does not reject, and its own grid certified where the served one was.
GateDecision gate_calibrated_candidate(const CalibratedModel& served, const CalibratedModel& candidate,
                                       const FastEvaluatorOptions& tolerances);
// P(X ≤ k) for X ~ Binomial(n, p), the gate's coverage test.
double binomial_lower_tail(long long k, long long n, double p);

}  // namespace mufric
