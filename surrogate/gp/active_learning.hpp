#pragma once
// Where to run the micro-model next: the candidates at which a trained GP is least certain.
// Greedy batch selection by the largest posterior variance ("active learning MacKay", MacKay,
// Neural Comput. 4, 1992; Seo et al., IJCNN 2000), each pick conditioning the next: a GP's posterior
// variance does not depend on the unobserved outputs, so after picking x* the covariance among the
// candidates is updated exactly, Σ ← Σ − Σ(:,x*) Σ(x*,:) / (Σ(x*,x*) + σn²) (R&W eq. 2.24 applied
// one point at a time), and the next pick avoids x*'s neighbourhood.
#include <vector>

#include <Eigen/Dense>

#include "surrogate/gp/gaussian_process.hpp"

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

// For stochastic simulators (a GP of the mean over draws, its samples' noise on the diagonal): greedy
// picks by the integrated variance of the mean each would remove, IMSE reduction (Ankenman, Nelson &
// Staum 2010, §5; Binois, Huang, Gramacy & Ludkovski 2019, Technometrics 61(1):7, "replication or
// exploration"). A candidate c observed with noise τ²_c removes, from the posterior variance at every
// reference point r, Σ(r, c)² / (Σ(c, c) + τ²_c) (R&W eq. 2.24 for one point), averaged over the
// reference points (a uniform set in the box: the integral over it). A candidate at an existing design
// point is a replicate (more draws there); elsewhere, a new point: the same formula chooses between
// them. Each pick conditions the next.
struct ImsePick {
  Eigen::Index candidate = 0;   // row of the candidate matrix
  double imse_reduction = 0.0;  // μ units², the mean posterior variance removed over the reference set
  double std_at_pick = 0.0;     // posterior std of the mean there, given the earlier picks
};
// candidate_noise: τ²_c of one sample at each candidate, μ units² (its per-draw variance / draws).
// reference: SI points spanning the box. tried: as for pick_by_posterior_variance.
std::vector<ImsePick> pick_by_imse_reduction(const GaussianProcess& gp, const Eigen::MatrixXd& candidates,
                                             const Eigen::VectorXd& candidate_noise, const Eigen::MatrixXd& reference,
                                             int batch, const Eigen::MatrixXd& tried = {});

}  // namespace mufric
