#include "micro/coupling/partitioned.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "common/error.hpp"

namespace mufric::coupling {

namespace {

// Aitken's factor is kept within this range: a secant estimate from nearly equal residuals can be
// wild, and a negative or huge ω would throw the iteration away.
constexpr double kAitkenOmegaMin = 1e-4, kAitkenOmegaMax = 1.0;

}  // namespace

InterfaceAccelerator::InterfaceAccelerator(CouplingOptions options) : options_(options) {
  if (!(options_.relaxation > 0.0 && options_.relaxation <= 1.0)) throw Error("coupling: relaxation must lie in (0, 1]");
  if (options_.reuse_steps < 0) throw Error("coupling: reuse_steps must not be negative");
  if (!(options_.qr_filter >= 0.0 && options_.qr_filter < 1.0)) throw Error("coupling: qr_filter must lie in [0, 1)");
}

void InterfaceAccelerator::begin_step() {
  residuals_.clear();
  outputs_.clear();
  relaxation_ = options_.relaxation;
  aitken_omega_ = relaxation_;
}

void InterfaceAccelerator::restart_step(double relaxation) {
  forget_past_steps();
  begin_step();
  relaxation_ = aitken_omega_ = relaxation;
}

void InterfaceAccelerator::end_step() {
  if (options_.acceleration != Acceleration::iqn_ils || options_.reuse_steps == 0 || residuals_.size() < 2) return;
  const auto n = static_cast<Eigen::Index>(residuals_.size()) - 1;
  Eigen::MatrixXd dr(residuals_.front().size(), n), dx(residuals_.front().size(), n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto s = static_cast<size_t>(i);
    dr.col(i) = residuals_[s + 1] - residuals_[s];
    dx.col(i) = outputs_[s + 1] - outputs_[s];
  }
  reused_.emplace_front(std::move(dr), std::move(dx));
  while (static_cast<int>(reused_.size()) > options_.reuse_steps) reused_.pop_back();
}

Eigen::VectorXd InterfaceAccelerator::next(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde) {
  const Eigen::VectorXd r = x_tilde - x;
  residuals_.push_back(r);
  outputs_.push_back(x_tilde);
  const size_t k = residuals_.size() - 1;
  columns_used_ = 0;
  switch (options_.acceleration) {
    case Acceleration::constant_relaxation:
      return x + relaxation_ * r;
    case Acceleration::aitken: {
      if (k > 0) {
        const Eigen::VectorXd dr = r - residuals_[k - 1];
        const double denominator = dr.squaredNorm();
        if (denominator > 0.0) {
          aitken_omega_ = std::clamp(-aitken_omega_ * residuals_[k - 1].dot(dr) / denominator, kAitkenOmegaMin, kAitkenOmegaMax);
        }
      }
      return x + aitken_omega_ * r;
    }
    case Acceleration::iqn_ils:
      break;
  }
  // Secant columns, newest first: this step's consecutive differences, then the reused steps'.
  std::vector<Eigen::VectorXd> v, w;
  for (size_t i = k; i > 0; --i) {
    v.push_back(residuals_[i] - residuals_[i - 1]);
    w.push_back(outputs_[i] - outputs_[i - 1]);
  }
  for (const auto& [dr, dx] : reused_) {
    for (Eigen::Index c = dr.cols() - 1; c >= 0; --c) v.emplace_back(dr.col(c)), w.emplace_back(dx.col(c));
  }
  if (v.empty()) return x + relaxation_ * r;
  // QR by modified Gram–Schmidt with the filter: a column that keeps less than qr_filter of its norm
  // after removing the newer columns' directions adds only noise to the least-squares model.
  std::vector<Eigen::VectorXd> q;
  std::vector<size_t> kept;
  Eigen::MatrixXd upper = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(v.size()), static_cast<Eigen::Index>(v.size()));
  for (size_t c = 0; c < v.size(); ++c) {
    Eigen::VectorXd u = v[c];
    const double original = u.norm();
    if (!(original > 0.0)) continue;
    Eigen::VectorXd coefficients(static_cast<Eigen::Index>(q.size()));
    for (size_t j = 0; j < q.size(); ++j) {
      coefficients(static_cast<Eigen::Index>(j)) = q[j].dot(u);
      u -= coefficients(static_cast<Eigen::Index>(j)) * q[j];
    }
    const double remaining = u.norm();
    if (remaining <= options_.qr_filter * original) continue;
    const auto col = static_cast<Eigen::Index>(kept.size());
    upper.col(col).head(col) = coefficients;
    upper(col, col) = remaining;
    q.push_back(u / remaining);
    kept.push_back(c);
  }
  if (kept.empty()) return x + relaxation_ * r;
  const auto m = static_cast<Eigen::Index>(kept.size());
  // min |V c + r|: R c = −Qᵀ r, then x_(k+1) = x̃ + W c.
  Eigen::VectorXd rhs(m);
  for (Eigen::Index j = 0; j < m; ++j) rhs(j) = -q[static_cast<size_t>(j)].dot(r);
  const Eigen::VectorXd c = upper.topLeftCorner(m, m).triangularView<Eigen::Upper>().solve(rhs);
  Eigen::VectorXd out = x_tilde;
  for (Eigen::Index j = 0; j < m; ++j) out += c(j) * w[kept[static_cast<size_t>(j)]];
  columns_used_ = static_cast<int>(m);
  return out;
}

CouplingStepReport coupled_step(const PartitionedSolvers& solvers, Eigen::VectorXd& load, Eigen::VectorXd& displacement,
                                InterfaceAccelerator& accelerator, const CouplingOptions& options) {
  CouplingStepReport report;
  const Eigen::VectorXd start_load = load, start = displacement;
  Eigen::VectorXd lambda = load, lambda_tilde, d, d_previous = displacement;
  // The last iterate both solvers took, and its image: where a restart goes back to.
  Eigen::VectorXd lambda_solved, lambda_tilde_solved;
  double restart_relaxation = options.relaxation;
  double best_load_residual = std::numeric_limits<double>::infinity();
  int best_iteration = 0;
  accelerator.begin_step();
  for (int it = 1; it <= options.max_iterations; ++it) {
    std::string reason;
    const char* failed = nullptr;
    if (!solvers.structure(lambda, d, reason)) {
      failed = "structure";
    } else if (!solvers.fluid(d, lambda, lambda_tilde, reason)) {
      failed = "fluid";
    }
    if (failed != nullptr) {
      if (lambda_solved.size() == 0 || report.restarts >= options.max_restarts) {
        report.reason = std::string(failed) + " solve failed at coupling iteration " + std::to_string(it) + ": " + reason;
        break;
      }
      // A safeguarded quasi-Newton: the accelerated iterate left the region the solvers can take
      // (a chip solve that cannot follow the load). Its secant model, this step's and the past
      // steps', has misled it: it is dropped, and the iteration restarts from the last solved
      // iterate with a relaxation halved at each restart, which tends to that solvable iterate.
      ++report.restarts;
      restart_relaxation *= 0.5;
      accelerator.restart_step(restart_relaxation);
      lambda = lambda_solved + restart_relaxation * (lambda_tilde_solved - lambda_solved);
      continue;
    }
    lambda_solved = lambda;
    lambda_tilde_solved = lambda_tilde;
    if (lambda_tilde.size() != lambda.size()) throw Error("coupling: the fluid returned a load of another size");
    report.iterations = it;
    const Eigen::VectorXd share = solvers.load_share ? solvers.load_share() : Eigen::VectorXd();
    if (share.size() != 0 && share.size() != lambda.size()) throw Error("coupling: the load share has another size than the load");
    const auto shared = [&share](const Eigen::VectorXd& x) {
      return share.size() == 0 ? Eigen::VectorXd(x) : Eigen::VectorXd(share.cwiseProduct(x));
    };
    const double load_residual = shared(lambda_tilde - lambda).norm();
    const double displacement_change = d_previous.size() == d.size() ? (d - d_previous).norm() : d.norm();
    report.load_residuals.push_back(load_residual);
    report.displacement_changes.push_back(displacement_change);
    if (!std::isfinite(load_residual) || !std::isfinite(displacement_change)) {
      report.reason = std::string(kInterfaceIterationFailed) + " diverged (non-finite) at exchange " + std::to_string(it);
      break;
    }
    const double components = static_cast<double>(std::max<Eigen::Index>(lambda_tilde.size(), 1));
    const bool load_converged = load_residual <= options.load_tolerance * std::sqrt(components) +
                                                     options.relative_tolerance * shared(lambda_tilde).norm();
    const bool displacement_converged =
        displacement_change <= options.displacement_tolerance +
                                   options.relative_tolerance * (start.size() == d.size() ? (d - start).norm() : d.norm());
    bool kinematics_converged = true;
    if (solvers.kinematic_residual) {
      const double kinematic = solvers.kinematic_residual();
      report.kinematic_residuals.push_back(kinematic);
      kinematics_converged = kinematic <= options.kinematic_tolerance;
    }
    if (load_converged && displacement_converged && kinematics_converged) {
      report.converged = true;
      load = lambda_tilde;
      displacement = d;
      accelerator.end_step();
      return report;
    }
    if (load_residual < best_load_residual) best_load_residual = load_residual, best_iteration = it;
    if (options.stall_iterations > 0 && it - best_iteration >= options.stall_iterations) {
      report.reason = std::string(kInterfaceIterationFailed) + " stalled: |load change| has stayed above its best of the step (" +
                      std::to_string(best_load_residual) + " Pa at exchange " + std::to_string(best_iteration) + ") for " +
                      std::to_string(options.stall_iterations) + " exchanges";
      break;
    }
    d_previous = d;
    lambda = accelerator.next(lambda, lambda_tilde);
  }
  if (report.reason.empty()) {
    report.reason = std::string(kInterfaceIterationFailed) + " did not converge in " + std::to_string(options.max_iterations) +
                    " exchanges";
  }
  load = start_load;
  displacement = start;
  return report;
}

bool is_interface_failure(std::string_view reason) { return reason.find(kInterfaceIterationFailed) != std::string_view::npos; }

}  // namespace mufric::coupling
