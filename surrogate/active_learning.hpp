#pragma once
// Where to run the micro-model next: the candidates at which a trained GP is least certain.
// Greedy batch selection by the largest posterior variance ("active learning MacKay", MacKay,
// Neural Comput. 4, 1992; Seo et al., IJCNN 2000), each pick conditioning the next: a GP's posterior
// variance does not depend on the unobserved outputs, so after picking x* the covariance among the
// candidates is updated exactly, Σ ← Σ − Σ(:,x*) Σ(x*,:) / (Σ(x*,x*) + σn²) (R&W eq. 2.24 applied
// one point at a time), and the next pick avoids x*'s neighbourhood.
#include <vector>

#include <Eigen/Dense>

#include "surrogate/gaussian_process.hpp"

namespace mufric {

struct VariancePick {
  Eigen::Index candidate = 0;  // row of the candidate matrix
  double std_at_pick = 0.0;    // posterior std of μ there (without noise), given the earlier picks
};

// `candidates` are SI points (rows) in the GP's input order; at most `batch` distinct picks.
// `tried` are points already run without a usable answer (failed runs): the variance is
// conditioned on them first, as if observed, so that the picks do not crowd where runs fail.
std::vector<VariancePick> pick_by_posterior_variance(const GaussianProcess& gp, const Eigen::MatrixXd& candidates,
                                                     int batch, const Eigen::MatrixXd& tried = {});

}  // namespace mufric
