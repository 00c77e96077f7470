#pragma once
// Helpers shared by the micro-solver tests.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "micro/solid/time_integrator.hpp"

namespace mufric::solid::test {

using numerics::LinearSolverKind;

// One quasi-static step of a linear problem, solved to 1e-13 of its force scale.
inline TimeIntegrationOptions static_step_options(LinearSolverKind solver = LinearSolverKind::lu) {
  TimeIntegrationOptions options;
  options.scheme = TimeScheme::quasi_static;
  options.dt = options.end_time = 1.0;
  options.relative_tolerance = 1e-13;
  options.linear_solver = solver;
  return options;
}

inline Eigen::VectorXd solve_static(SolidProblem& problem, LinearSolverKind solver = LinearSolverKind::lu) {
  TimeIntegrator integrator(problem, static_step_options(solver));
  const IntegrationReport report = integrator.run();
  EXPECT_TRUE(report.completed) << report.reason;
  return integrator.u();
}

// K w against central differences of the assembled internal (+ interaction) forces.
inline void expect_tangent_matches_finite_differences(const SolidProblem& problem, const Eigen::VectorXd& u, double dt,
                                                      const std::string& what, double tolerance = 2e-6) {
  const auto at = problem.assemble(u, dt, true);
  ASSERT_TRUE(at.ok) << at.reason;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd w(u.size());
    for (auto& x : w) x = normal(rng);
    const double h = 1e-7 * (u.cwiseAbs().maxCoeff() + 1e-9) / w.cwiseAbs().maxCoeff();
    const Eigen::VectorXd fd =
        (problem.assemble(u + h * w, dt, false).internal - problem.assemble(u - h * w, dt, false).internal) / (2 * h);
    const Eigen::VectorXd kw = problem.tangent_storage() == numerics::MatrixStorage::full
                                   ? Eigen::VectorXd(at.tangent * w)
                                   : Eigen::VectorXd(at.tangent.selfadjointView<Eigen::Lower>() * w);
    const double mismatch = std::sqrt((kw - fd).squaredNorm()), size = std::sqrt(kw.squaredNorm());
    EXPECT_LT(mismatch, tolerance * size) << what;
  }
}

}  // namespace mufric::solid::test
