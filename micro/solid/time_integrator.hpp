#pragma once
// Time stepping of a SolidProblem: generalized-α (Chung & Hulbert, J. Appl. Mech. 60, 1993) with
// the internal force averaged between step ends (the form that suits path-dependent materials,
// Erlicher, Bonaventura & Bursi, Comput. Mech. 28, 2002), or quasi-static. Each step is solved by
// Newton's method with a line search on the quadratic variation of the residual norm (a quadratic
// model of ‖G(u + sδ)‖² in the step length, Dennis & Schnabel 1996, A6.3.1); a step that fails
// is cut in half and retried, and every cut-back is reported.
#include <functional>
#include <string>
#include <vector>

#include "micro/numerics/linear_solver.hpp"
#include "micro/solid/solid_problem.hpp"

namespace mufric::solid {

enum class TimeScheme { generalized_alpha, quasi_static };

// Newton stops when the free-dof residual is below relative × the force scale of the step (the
// largest of internal, external and inertial force norms seen), or when an increment is below
// kNewtonStagnationIncrement × |u| while the residual is within 1000× that tolerance.
inline constexpr double kNewtonStagnationIncrement = 1e-14;
inline constexpr double kLineSearchSufficientDecrease = 1e-4;  // Armijo constant on ‖G‖²
inline constexpr int kLineSearchMaxReductions = 8;
// With LU, the factorisation of the previous iteration is reused (a chord step) when that iteration
// took a full step and cut the residual below this fraction: measured on the default scene (60 ns,
// UMFPACK), 0.05 saved 11 % of the run time for 6 % more iterations; 0.3 doubled the iterations.
// With Cholesky full Newton's quadratic convergence is cheaper, so there are no chord steps (the
// 128 × 24 default scene: 753 Newton iterations instead of 923 with them, and 2 % faster).
inline constexpr double kReuseFactorizationBelow = 0.05;
// Step-size control by Newton iteration count (the iteration-count heuristic of e.g. Wriggers,
// Nonlinear Finite Element Methods 2008, sec. 5.2.3, and Abaqus' automatic incrementation): the next
// step is the last one × kTargetNewtonIterations / iterations, within [1/2, 2] and at most max_dt.
// Steps that needed many iterations shrink before they fail, but not below dt ×
// kShortestControlledStep: where iterations stay high however short the step (an active contact set
// that keeps changing), shrinking further would only multiply the steps. Cut-backs go below it.
inline constexpr int kTargetNewtonIterations = 8;
inline constexpr double kMaxStepGrowth = 2.0, kMaxStepShrink = 0.5;
inline constexpr double kShortestControlledStep = 0.25;
// A Newton trial whose quadratic-convergence prediction is below this fraction of the tolerance is
// evaluated without its tangent (it is expected to end the step).
inline constexpr double kPredictedConvergenceMargin = 0.1;
// Newton's forcing term for an iteratively solved (unsymmetric) tangent: the linear residual each
// solve may leave, η_k = γ (‖G_k‖/‖G_{k−1}‖)² (Eisenstat & Walker, SIAM J. Sci. Comput. 17, 1996,
// choice 2, γ = 0.9), at most kMaxForcing, and never below what still reaches the tolerance,
// 0.5 tol/‖G_k‖ (Kelley, Iterative Methods for Linear and Nonlinear Equations, 1995, eq. 6.20).
inline constexpr double kForcingGamma = 0.9;
inline constexpr double kMaxForcing = 1e-2;

class TimeIntegrator;

struct TimeIntegrationOptions {
  TimeScheme scheme = TimeScheme::generalized_alpha;
  double spectral_radius = 0.8;  // ρ∞ ∈ [0, 1]: 1 conserves energy (trapezoidal), 0 damps the highest modes at once
  double dt = 1e-8;              // s, the first step
  double max_dt = 0.0;           // s, the longest step the controller may take (0: dt)
  // When set, the longest step for a step starting at time t (overrides max_dt): a protocol whose
  // phases need different steps, e.g. steps sized by sliding distance once sliding starts.
  std::function<double(double)> max_dt_at;
  // Called after every accepted step (t at its end, its length, u at its end), before on_step: a
  // field solved staggered with the mechanics, e.g. heat conduction updating the committed states.
  // false (with a reason) ends the run as not completed.
  std::function<bool(double t, double dt, const Eigen::VectorXd& u, std::string& reason)> after_step;
  // When set, a step coupled with another field (the lubricant): called instead of one Newton solve
  // of the step from t0 over dt, with the integrator itself, whose solve_trial(t0, dt, …) it may call
  // any number of times (each from the step's start, with whatever loads it set in between). It
  // returns false with a reason when the coupled step fails (cut back like any failed step); on true,
  // the last trial is accepted. (The partner owns its exchange loop, as a preCICE participant does;
  // the integrator owns time.)
  std::function<bool(TimeIntegrator& integrator, double t0, double dt, std::string& reason)> coupled_step;
  // When set, asked after every failed attempt, before the step is cut back: true (with a reason)
  // ends the run as not completed. A wall-time limit, so that a step that keeps failing does not
  // outlast it by up to max_cutbacks more attempts (accepted steps are the caller's to check).
  std::function<bool(std::string& reason)> should_stop;
  double end_time = 1e-7;        // s
  double relative_tolerance = 1e-9;
  int max_newton_iterations = 30;
  bool line_search = true;
  int max_cutbacks = 8;          // consecutive halvings of a failing step before giving up
  numerics::LinearSolverKind linear_solver = numerics::LinearSolverKind::lu;
};

struct StepRecord {
  double time = 0.0, dt = 0.0;
  int newton_iterations = 0, line_search_reductions = 0;
  double residual = 0.0;  // final free-dof residual norm, N
};

struct CutBack {
  double time = 0.0, dt_failed = 0.0;
  std::string reason;
};

struct IntegrationReport {
  bool completed = false;
  std::string reason;  // why not completed
  std::vector<StepRecord> steps;
  std::vector<CutBack> cutbacks;
  int newton_iterations = 0;
  int symbolic_analyses = 0;  // sparse symbolic factorisations (1 per run: the pattern is fixed)
  int lu_fallbacks = 0;       // Cholesky runs: tangents CHOLMOD found not positive definite (solved by LU)
  int krylov_iterations = 0;  // Cholesky runs with an unsymmetric tangent: BiCGSTAB iterations, all solves
  int assemblies = 0;              // residual evaluations (with or without tangent)
  int line_search_reductions = 0;
  int unpredicted_convergence = 0;  // trials expected to converge that did not (evaluated twice)
  double seconds_assembly = 0.0, seconds_solve = 0.0;
  double seconds_contact = 0.0;    // part of seconds_assembly spent in boundary interactions
  double seconds_after_step = 0.0; // in options.after_step (a staggered field: heat conduction)
};

// The fields at the end of an accepted step, for callers that watch the run.
struct StepView {
  double time;
  const Eigen::VectorXd& u;
  const Eigen::VectorXd& v;
  const Eigen::VectorXd& a;
  const Eigen::VectorXd& reactions;  // −residual at the constrained dofs (forces the supports exert)
  // Stress S at every quadrature point as computed in the step (re-evaluating the material from the
  // committed state would not reproduce a rate-dependent stress).
  const std::vector<Eigen::Matrix2d>& stresses;
  const SolidProblem& problem;
};

class TimeIntegrator {
 public:
  TimeIntegrator(SolidProblem& problem, TimeIntegrationOptions options);
  // Initial fields (default zero); the initial acceleration is solved from M a = F − f_int.
  void set_initial(const Eigen::VectorXd& u, const Eigen::VectorXd& v);
  IntegrationReport run(const std::function<void(const StepView&)>& on_step = {});
  const Eigen::VectorXd& u() const { return u_; }
  const Eigen::VectorXd& v() const { return v_; }
  const std::vector<Eigen::Matrix2d>& stresses() const { return stresses_; }  // of the last accepted step

  // For options.coupled_step: solves the step from t0 over dt with the current loads, from the last
  // accepted state, without accepting it. The trial's displacement and velocity are trial_u() and
  // trial_v(); false with a reason when Newton fails.
  bool solve_trial(double t0, double dt, std::string& reason);
  const Eigen::VectorXd& trial_u() const { return trial_.u; }
  Eigen::VectorXd trial_v() const;

 private:
  struct Attempt {
    bool ok = false;
    std::string reason;
    StepRecord record;
  };
  // A solved step not yet accepted.
  struct Trial {
    double t0 = 0.0, dt = 0.0;
    bool valid = false;
    Eigen::VectorXd u, a, internal, residual;
    std::vector<MaterialState> states;
    std::vector<Eigen::Matrix2d> stresses;
    int newton_iterations = 0, line_search_reductions = 0;  // summed over the trials of one step
    int last_newton_iterations = 0;                          // of the last trial alone
    double residual_norm = 0.0;
  };
  // What stays fixed over one step's Newton iterations.
  struct StepSystem {
    bool dynamic = false;
    double dt = 0.0, t1 = 0.0;
    Eigen::VectorXd f_ext0, f_ext1;
    numerics::MatrixStorage storage = numerics::MatrixStorage::lower_symmetric;
    numerics::Symmetry symmetry = numerics::Symmetry::symmetric;
    const SparseMatrix* mass = nullptr;          // dynamic: M (lower triangle)
    const SparseMatrix* tangent_mass = nullptr;  // dynamic: M in the tangent's storage
    double mass_factor = 0.0, stiffness_factor = 1.0;  // K_eff = stiffness_factor K + mass_factor M
  };
  // The residual G(u1) and what comes with it.
  struct Evaluation {
    SolidProblem::Assembly assembly;
    Eigen::VectorXd residual, a1;
    double norm = 0.0, scale = 0.0;
  };
  struct LineSearch {
    Evaluation trial;   // at u + step δ
    double step = 1.0;
    bool has_tangent = false;
  };
  Attempt solve(double t0, double dt);  // into trial_: Newton's loop over the steps below
  Eigen::VectorXd predictor(double t0, double dt) const;
  StepSystem step_system(double t0, double dt) const;
  Evaluation evaluate(const StepSystem& sys, const Eigen::VectorXd& u, bool with_tangent,
                      const std::vector<MaterialState>* guesses);
  bool factorize_tangent(const StepSystem& sys, MovableSparseMatrix k, std::string& reason);
  static double forcing_term(int iteration, double norm, double previous_norm, double tolerance);
  LineSearch line_search(const StepSystem& sys, const Eigen::VectorXd& u, const Eigen::VectorXd& delta, double norm,
                         bool with_tangent, const std::vector<MaterialState>* guesses, StepRecord& record);
  void keep_trial(double t0, double dt, Eigen::VectorXd u1, Evaluation&& solved, const StepRecord& record);
  void accept();                        // trial_ becomes the state
  Attempt step(double t0, double dt);   // solve + accept, or the coupled step
  Trial trial_;
  double next_step(double t, double dt, int newton_iterations) const;
  void record_solver_counts();  // the linear solver's counters into report_
  double alpha_m() const, alpha_f() const, beta() const, gamma() const;
  SolidProblem& problem_;
  TimeIntegrationOptions options_;
  Eigen::VectorXd u_, v_, a_, f_int_, reactions_;
  Eigen::VectorXd last_increment_;  // u of the last accepted step minus u before it
  double last_dt_ = 0.0;            // its length; 0 before the first accepted step
  std::vector<Eigen::Matrix2d> stresses_;
  numerics::LinearSolver solver_;
  IntegrationReport report_;
};

}  // namespace mufric::solid
