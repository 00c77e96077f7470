#pragma once
// Markov-chain Monte Carlo for a calibration's posterior: the affine-invariant ensemble sampler
// (Goodman & Weare 2010, Commun. Appl. Math. Comput. Sci. 5(1):65, the stretch move of §3), and the
// diagnostics its chains are judged by before anyone reads them: split-R̂ (Gelman et al., Bayesian
// Data Analysis, 3rd ed., §11.4) and the effective sample size from the integrated autocorrelation
// time with Sokal's automatic window (Sokal 1997, Monte Carlo Methods in Statistical Mechanics, §3;
// the ensemble form of Foreman-Mackey et al. 2013, PASP 125:306).
//
// Affine invariance is why this sampler: a law's coefficients are scaled and correlated with one
// another (a shear factor and an adhesive coefficient trade off against each other along a ridge),
// and the stretch move samples a stretched, rotated Gaussian as fast as a round one, with one tuning
// constant and no step sizes to choose.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace mufric {

// The log of an unnormalised density; −∞ (not NaN) outside its support.
using LogDensity = std::function<double(const Eigen::VectorXd&)>;

struct EnsembleOptions {
  int walkers = 32;          // at least twice the dimension plus one (checked)
  int burn_in_steps = 500;   // steps discarded; every walker moves once per step
  int steps = 1500;          // steps kept
  double stretch = 2.0;      // a in g(z) ∝ 1/√z on [1/a, a]; Goodman & Weare's value
  std::uint64_t seed = 1;    // the whole run (start and moves) follows from it, bit for bit
  // calibrate() only: a run that fails the convergence limits is continued, its length doubling, up
  // to this many steps in all (0: never), and judged on its latest part (CalibrationResult says).
  int max_steps = 0;
};

struct EnsembleChains {
  // Walker w's kept states, steps × dimension, and their log densities.
  std::vector<Eigen::MatrixXd> states;
  std::vector<Eigen::VectorXd> log_density;
  double acceptance = 0.0;  // accepted fraction of the kept steps' proposals
  Eigen::Index dimension() const { return states.empty() ? 0 : states.front().cols(); }
  Eigen::Index steps() const { return states.empty() ? 0 : states.front().rows(); }
  // Every walker's kept states stacked: (walkers × steps) × dimension.
  Eigen::MatrixXd pooled() const;
};

// Called after each step with (steps done, steps in all); may be empty.
using SamplerProgress = std::function<void(int done, int total)>;

// Runs the ensemble from `start` (walkers × dimension; every row of finite log density, checked:
// the error names the row). Sequential stretch moves (each walker against the others' current
// states), one core, deterministic given the options.
EnsembleChains run_ensemble_sampler(const LogDensity& log_density, const Eigen::MatrixXd& start,
                                    const EnsembleOptions& options, const SamplerProgress& progress = {});

// split-R̂ of one coordinate over several chains of equal length: each halved, so that a chain still
// drifting counts as two chains that disagree (BDA3 eq. 11.4). 1 when they agree; NaN for chains of
// fewer than 4 states.
double split_rhat(const std::vector<Eigen::VectorXd>& chains);

// τ = 1 + 2 Σ_{t=1}^{M} ρ(t) of one coordinate, ρ the autocorrelation averaged over the chains, and
// M the smallest window with M ≥ c τ(M) (Sokal's automatic window, c = 5). An AR(1) chain of
// coefficient φ has τ = (1 + φ)/(1 − φ).
double integrated_autocorrelation_time(const std::vector<Eigen::VectorXd>& chains);

// Per coordinate; effective sample size = walkers × steps / τ.
struct ChainDiagnostics {
  Eigen::VectorXd split_rhat;
  Eigen::VectorXd autocorrelation_time;
  Eigen::VectorXd effective_sample_size;
};
ChainDiagnostics diagnose_chains(const EnsembleChains& chains);

// The limits a posterior must meet to be used, and why one fails them: "" when it meets them, else
// the first coordinate that does not, by its name, with the figure, the limit and what to change.
inline constexpr double kMaximumSplitRhat = 1.05;       // BDA3 recommends 1.1; tighter, runs are cheap
inline constexpr double kMinimumEffectiveSamples = 400;  // a mean's Monte Carlo error 1/√400 = 5 % of its SD
inline constexpr double kMinimumStepsPerAutocorrelationTime = 20;  // shorter chains misjudge τ itself
std::string convergence_failure(const ChainDiagnostics& diagnostics, const std::vector<std::string>& names,
                                Eigen::Index steps);

// A uniform double in [0, 1) from the generator's top 53 bits (not std::uniform_real_distribution,
// whose algorithm the standard leaves open: a seed must give the same posterior on every library).
double uniform01(std::uint64_t bits);

}  // namespace mufric
