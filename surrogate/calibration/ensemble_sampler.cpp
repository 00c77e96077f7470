#include "surrogate/calibration/ensemble_sampler.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "common/error.hpp"

namespace mufric {
namespace {

// Sokal's window constant: the sum stops at the first lag M ≥ c τ(M).
constexpr double kSokalWindow = 5.0;

// z with density ∝ 1/√z on [1/a, a]: z = ((a − 1) u + 1)² / a (Goodman & Weare 2010, eq. 9).
double stretch_factor(double a, double u) {
  const double root = (a - 1.0) * u + 1.0;
  return root * root / a;
}

// Sample variance with the n − 1 divisor.
double sample_variance(const Eigen::VectorXd& x) {
  const double mean = x.mean();
  return (x.array() - mean).square().sum() / static_cast<double>(x.size() - 1);
}

}  // namespace

double uniform01(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

Eigen::MatrixXd EnsembleChains::pooled() const {
  Eigen::MatrixXd all(static_cast<Eigen::Index>(states.size()) * steps(), dimension());
  for (size_t w = 0; w < states.size(); ++w) all.middleRows(static_cast<Eigen::Index>(w) * steps(), steps()) = states[w];
  return all;
}

EnsembleChains run_ensemble_sampler(const LogDensity& log_density, const Eigen::MatrixXd& start,
                                    const EnsembleOptions& options, const SamplerProgress& progress) {
  const Eigen::Index walkers = start.rows(), dimension = start.cols();
  if (dimension < 1) throw Error("ensemble sampler: no parameters to sample");
  if (walkers != options.walkers) {
    throw Error("ensemble sampler: the start has " + std::to_string(walkers) + " rows for " +
                std::to_string(options.walkers) + " walkers");
  }
  if (walkers < 2 * dimension + 1) {
    throw Error("ensemble sampler: " + std::to_string(walkers) + " walkers for " + std::to_string(dimension) +
                " parameters; at least " + std::to_string(2 * dimension + 1) + " are needed (walkers)");
  }
  if (options.steps < 4 || options.burn_in_steps < 0) throw Error("ensemble sampler: steps must be at least 4, burn-in at least 0");
  if (!(options.stretch > 1.0)) throw Error("ensemble sampler: the stretch constant must exceed 1");

  Eigen::MatrixXd position = start;
  Eigen::VectorXd current(walkers);
  for (Eigen::Index w = 0; w < walkers; ++w) {
    current(w) = log_density(position.row(w).transpose());
    if (!std::isfinite(current(w))) {
      throw Error("ensemble sampler: walker " + std::to_string(w) + "'s start has no finite log density");
    }
  }
  EnsembleChains chains;
  chains.states.assign(static_cast<size_t>(walkers), Eigen::MatrixXd(options.steps, dimension));
  chains.log_density.assign(static_cast<size_t>(walkers), Eigen::VectorXd(options.steps));
  std::mt19937_64 random(options.seed);
  const int total = options.burn_in_steps + options.steps;
  long long accepted = 0;
  Eigen::VectorXd proposal(dimension);
  for (int step = 0; step < total; ++step) {
    const bool kept = step >= options.burn_in_steps;
    for (Eigen::Index w = 0; w < walkers; ++w) {
      // Another walker, uniformly among the rest.
      auto other = static_cast<Eigen::Index>(uniform01(random()) * static_cast<double>(walkers - 1));
      if (other >= w) ++other;
      const double z = stretch_factor(options.stretch, uniform01(random()));
      proposal = position.row(other).transpose() + z * (position.row(w) - position.row(other)).transpose();
      const double proposed = log_density(proposal);
      // Accept with probability min(1, z^(d−1) p(Y)/p(X)) (eq. 7): log u < (d − 1) log z + Δ.
      const double log_ratio = static_cast<double>(dimension - 1) * std::log(z) + proposed - current(w);
      if (std::isfinite(proposed) && std::log(uniform01(random())) < log_ratio) {
        position.row(w) = proposal.transpose();
        current(w) = proposed;
        if (kept) ++accepted;
      }
      if (kept) {
        chains.states[static_cast<size_t>(w)].row(step - options.burn_in_steps) = position.row(w);
        chains.log_density[static_cast<size_t>(w)](step - options.burn_in_steps) = current(w);
      }
    }
    if (progress) progress(step + 1, total);
  }
  chains.acceptance = static_cast<double>(accepted) / static_cast<double>(walkers * options.steps);
  return chains;
}

double split_rhat(const std::vector<Eigen::VectorXd>& chains) {
  if (chains.empty() || chains.front().size() < 4) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Index half = chains.front().size() / 2;
  std::vector<Eigen::VectorXd> halves;
  for (const Eigen::VectorXd& chain : chains) {
    halves.emplace_back(chain.head(half));
    halves.emplace_back(chain.tail(half));
  }
  const auto n = static_cast<double>(half);
  Eigen::VectorXd means(halves.size()), variances(halves.size());
  for (size_t j = 0; j < halves.size(); ++j) {
    means(static_cast<Eigen::Index>(j)) = halves[j].mean();
    variances(static_cast<Eigen::Index>(j)) = sample_variance(halves[j]);
  }
  const double within = variances.mean();                 // W
  const double between = n * sample_variance(means);      // B
  if (within <= 0.0) return between > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  const double pooled = (n - 1.0) / n * within + between / n;  // var⁺ (BDA3 eq. 11.3)
  return std::sqrt(pooled / within);
}

double integrated_autocorrelation_time(const std::vector<Eigen::VectorXd>& chains) {
  if (chains.empty() || chains.front().size() < 2) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Index n = chains.front().size();
  // The autocovariance at each lag, averaged over the chains, each about its own mean.
  std::vector<Eigen::VectorXd> centred;
  for (const Eigen::VectorXd& chain : chains) centred.emplace_back(chain.array() - chain.mean());
  auto autocovariance = [&](Eigen::Index lag) {
    double sum = 0.0;
    for (const Eigen::VectorXd& c : centred) sum += c.head(n - lag).dot(c.tail(n - lag));
    return sum / static_cast<double>(n * static_cast<Eigen::Index>(centred.size()));
  };
  const double variance = autocovariance(0);
  if (variance <= 0.0) return 1.0;  // a constant coordinate: nothing to correlate
  double tau = 1.0;
  for (Eigen::Index lag = 1; lag < n; ++lag) {
    tau += 2.0 * autocovariance(lag) / variance;
    if (static_cast<double>(lag) >= kSokalWindow * tau) return tau;
  }
  return tau;  // the window never closed: the chain is too short for τ, as convergence_failure says
}

ChainDiagnostics diagnose_chains(const EnsembleChains& chains) {
  const Eigen::Index d = chains.dimension();
  ChainDiagnostics out{Eigen::VectorXd(d), Eigen::VectorXd(d), Eigen::VectorXd(d)};
  const double draws = static_cast<double>(chains.states.size()) * static_cast<double>(chains.steps());
  for (Eigen::Index k = 0; k < d; ++k) {
    std::vector<Eigen::VectorXd> coordinate;
    for (const Eigen::MatrixXd& walker : chains.states) coordinate.emplace_back(walker.col(k));
    out.split_rhat(k) = split_rhat(coordinate);
    out.autocorrelation_time(k) = integrated_autocorrelation_time(coordinate);
    out.effective_sample_size(k) = draws / std::max(1.0, out.autocorrelation_time(k));
  }
  return out;
}

std::string convergence_failure(const ChainDiagnostics& diagnostics, const std::vector<std::string>& names,
                                Eigen::Index steps) {
  std::ostringstream why;
  for (Eigen::Index k = 0; k < diagnostics.split_rhat.size(); ++k) {
    const std::string& name = names.at(static_cast<size_t>(k));
    const double rhat = diagnostics.split_rhat(k), tau = diagnostics.autocorrelation_time(k);
    const double ess = diagnostics.effective_sample_size(k);
    if (!(rhat <= kMaximumSplitRhat)) {
      why << name << ": split-R̂ " << rhat << " > " << kMaximumSplitRhat
          << ": the walkers have not mixed (more burn-in steps; or the data cannot tell this parameter from another "
             "along a ridge or between modes: an informative prior, or fewer calibrated inputs)";
      return why.str();
    }
    if (!(static_cast<double>(steps) >= kMinimumStepsPerAutocorrelationTime * tau)) {
      why << name << ": " << steps << " steps are " << static_cast<double>(steps) / tau
          << " autocorrelation times (τ = " << tau << "), fewer than " << kMinimumStepsPerAutocorrelationTime
          << ": run more steps";
      return why.str();
    }
    if (!(ess >= kMinimumEffectiveSamples)) {
      why << name << ": effective sample size " << ess << " < " << kMinimumEffectiveSamples
          << ": run more steps or walkers";
      return why.str();
    }
  }
  return "";
}

}  // namespace mufric
