#pragma once
// How well a calibration predicts each measurement it did not see, without rerunning it: Pareto-
// smoothed importance-sampling leave-one-out (PSIS-LOO; Vehtari, Simpson, Gelman, Yao & Gabry 2024,
// J. Mach. Learn. Res. 25:72) on the Kennedy–O'Hagan likelihood, which does not factorise over the
// rows (δ and the emulator's interval correlate them): the pointwise term is each row's normal
// predictive given the others at a posterior point, in closed form from the precision matrix
// (Bürkner, Gabry & Vehtari 2021, Comput. Stat. 36:1243, eqs. 7-8; Sundararajan & Keerthi 2001).
// The expected log predictive density (elpd) compares law variants on the same rows (higher is
// better), as held-out error does, in one run.
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "surrogate/calibration/calibration.hpp"

namespace mufric {

// A Pareto k̂ above this makes the row's importance-sampling estimate unreliable (Vehtari et al.
// 2024, sec. 3): its held-out figures are then a refit's to make, and said so.
inline constexpr double kParetoKUnreliable = 0.7;

// Pareto-smoothed log weights (normalised: their exp sums to 1) of importance ratios given as logs,
// and the tail's shape k̂ (∞ when the tail is too short to fit).
struct SmoothedWeights {
  Eigen::VectorXd log_weights;
  double pareto_k = 0.0;
};
SmoothedWeights pareto_smoothed_weights(const Eigen::VectorXd& log_ratios);

struct RowHeldOut {
  double elpd = 0.0;            // log p(y_i | y_−i)
  double pareto_k = 0.0;
  double predicted_mean = 0.0;  // the row's predictive given the others: its mean and SD (incl. its own SD)
  double predicted_sd = 0.0;
};

struct HeldOutCheck {
  std::vector<RowHeldOut> rows;
  double elpd = 0.0, elpd_se = 0.0;  // Σ elpd_i and its SE (√n · SD of the elpd_i)
  double p_loo = 0.0;                // the effective number of parameters: lppd − elpd
  double mean_abs_error = 0.0;       // mean |y_i − predicted mean|
  double covered = 0.0;              // share of rows within their predictive's 95 % (normal) interval
  int unreliable = 0;                // rows with k̂ > kParetoKUnreliable
  int samples = 0;                   // posterior points used
};

// On at most max_samples of the kept states, evenly spaced.
HeldOutCheck leave_one_out(const CalibrationProblem& problem, const CalibrationResult& result, int max_samples = 4000);

// The pointwise term at a posterior point: log p(y_i | y_−i, point) and that predictive's mean and
// variance, for every row.
struct ConditionalPredictives {
  Eigen::VectorXd log_density, mean, variance;
};
ConditionalPredictives conditional_predictives(const CalibrationProblem& problem, const Eigen::VectorXd& natural);

std::string describe_held_out(const CalibrationProblem& problem, const HeldOutCheck& check);

}  // namespace mufric
