#pragma once
// Small deterministic data sets for GP tests.
#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "common/dataset_file.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric::test {

// A smooth μ-like field on the seed-000 box (SI inputs), no physics: only for numerical tests.
inline double smooth_field(double p, double v, double t) {
  const double ps = (p - 300e6) / 1000e6, vs = (v - 0.375) / 2.958, ts = (t - 298.15) / 875.0;
  return 0.3 - 0.08 * ps + 0.05 * std::sin(3.0 * vs) + 0.1 * std::exp(-2.0 * ts) * (1.0 + 0.3 * ps * vs);
}

inline TrainingSet smooth_training_set(Eigen::Index n, unsigned seed) {
  TrainingSet t;
  t.inputs = default_friction_box();
  t.x.resize(n, 3);
  t.mu.resize(n);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < 3; ++j) {
      const auto& in = t.inputs[static_cast<size_t>(j)];
      t.x(i, j) = in.lo + u(rng) * (in.hi - in.lo);
    }
    t.mu(i) = smooth_field(t.x(i, 0), t.x(i, 1), t.x(i, 2));
  }
  t.source_path = "synthetic";
  return t;
}

// Stochastic kriging with given hyper-parameters (not optimised): each sample's μ_std² on the
// diagonal, the interval the mean's.
inline GpTrainingOptions fixed_stochastic_kriging(double signal_variance, const Eigen::Vector3d& length_scales,
                                                  double noise_variance) {
  GpTrainingOptions o;
  o.optimise = false;
  o.sample_noise = true;
  o.interval_of_mean = true;
  o.initial.signal_variance = signal_variance;
  o.initial.length_scales = length_scales;
  o.initial.noise_variance = noise_variance;
  return o;
}

// A GP with these hyper-parameters (not optimised) on smooth_training_set(n, seed).
inline GaussianProcess fixed_hyper_gp(Eigen::Index n, unsigned seed, double signal_variance,
                                      const Eigen::Vector3d& length_scales, double noise_variance) {
  GpTrainingOptions o;
  o.optimise = false;
  o.initial.signal_variance = signal_variance;
  o.initial.length_scales = length_scales;
  o.initial.noise_variance = noise_variance;
  return train_gaussian_process(smooth_training_set(n, seed), o);
}

}  // namespace mufric::test
