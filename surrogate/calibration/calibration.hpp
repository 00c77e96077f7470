#pragma once
// Bayesian calibration of a simulator's parameters θ through its GP emulator (Kennedy & O'Hagan
// 2001, J. R. Stat. Soc. B 63:425, eq. 5; the emulator's joint posterior in the likelihood as in
// Higdon et al. 2004, SIAM J. Sci. Comput. 26:448, §2):
//
//   y_i = η(x_i, θ) + δ(x_i) + b_{k(i)} + ε_i,   ε_i ~ N(0, s_i²),   δ ~ GP(0, σ_δ² exp(−½ |u − u'|² / ℓ_δ²)),
//
// x the measurement's conditions (contact pressure, sliding velocity, temperature), u their unit-box
// coordinates in the emulator's box, s_i the measurement's own standard deviation, b_k the bias of
// data set k (a set that measures something else than the reference, e.g. a tribometer's μ beside
// a cut's rake-face μ; 0 for a set given no bias). With η's GP posterior (mean m, covariance C_η:
// the interval of the mean over the roughness draws),
//
//   y | θ, σ_δ, ℓ_δ, b, x ~ N(m(X, θ) + b, C_η(X, θ) + K_δ(X) + diag(s²)),
//
// and the posterior of (θ, σ_δ, ℓ_δ, b) is sampled with the ensemble sampler. δ can be switched off
// (σ_δ = 0): then θ alone must explain the data within the measurement's and the emulator's errors.
// A condition known only within an uncertainty (an interface temperature estimated by a model) is a
// latent coordinate of its own with that uncertainty as its prior, sampled with the rest (errors in
// variables: the structural approach, Carroll, Ruppert, Stefanski & Crainiceanu, Measurement Error
// in Nonlinear Models, 2nd ed. 2006, ch. 9).
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "surrogate/calibration/calibration_problem.hpp"
#include "surrogate/calibration/ensemble_sampler.hpp"
#include "surrogate/calibration/measurements.hpp"
#include "surrogate/calibration/priors.hpp"

namespace mufric {

struct ParameterSummary {
  std::string name;
  double mean = 0.0, sd = 0.0, lo95 = 0.0, hi95 = 0.0, median = 0.0;  // natural units (SI; σ_δ, ℓ_δ themselves)
  double split_rhat = 0.0, effective_sample_size = 0.0;
};

struct CalibrationResult {
  std::vector<ParameterSummary> summary;  // per coordinate
  Eigen::MatrixXd samples;  // pooled kept states, natural units (σ_δ, ℓ_δ, not their logs)
  double acceptance = 0.0;
  ChainDiagnostics diagnostics;
  // "" when the chains meet the limits (ensemble_sampler.hpp), else why not, naming the coordinate.
  std::string convergence_failure;
  // As run: after a continuation (EnsembleOptions::max_steps) the steps kept and the burn-in before them.
  EnsembleOptions options;
};

// One quantile of sorted values, by linear interpolation between order statistics (Hyndman & Fan
// 1996, definition 7, R's default).
double quantile_of_sorted(const std::vector<double>& sorted, double probability);

// Samples the problem's posterior: stretch moves over every coordinate, the latent conditions with
// the rest (per-row Metropolis-within-Gibbs blocks for them were measured no faster for θ, whose
// mixing sets the run's length: bench/studies/calibration/README.md, "Conditions with uncertainty").
CalibrationResult calibrate(const CalibrationProblem& problem, const EnsembleOptions& options,
                            const SamplerProgress& progress = {});

}  // namespace mufric
