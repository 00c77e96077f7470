#include "micro/solid/time_integrator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "common/blas_threads.hpp"
#include "common/environment.hpp"
#include "common/error.hpp"

namespace mufric::solid {
namespace {

// MUFRIC_TRACE_NEWTON=1 prints every Newton iteration's residual to stderr (diagnosing a run).
bool trace_newton() {
  static const bool on = environment_flag("MUFRIC_TRACE_NEWTON");
  return on;
}

// A micro run lasts nanoseconds: "t = 0.000000 s" (std::to_string) hid where a step failed.
std::string time_label(double t_s) {
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "t = %.6g ns", t_s * 1e9);
  return buffer;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double free_norm(const Eigen::VectorXd& g, const std::vector<bool>& constrained) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < g.size(); ++i) {
    if (!constrained[static_cast<size_t>(i)]) s += g(i) * g(i);
  }
  return std::sqrt(s);
}

}  // namespace

TimeIntegrator::TimeIntegrator(SolidProblem& problem, TimeIntegrationOptions options)
    : problem_(problem), options_(options), solver_(options.linear_solver) {
  if (!(options_.dt > 0.0) || !(options_.end_time > 0.0)) throw Error("time integration: dt and end_time must be positive");
  if (!(options_.spectral_radius >= 0.0 && options_.spectral_radius <= 1.0)) {
    throw Error("time integration: the spectral radius must lie in [0, 1]");
  }
  const auto n = problem_.dof_count();
  u_ = v_ = a_ = reactions_ = Eigen::VectorXd::Zero(n);
  f_int_ = problem_.assemble(u_, options_.dt, false).internal;
}

double TimeIntegrator::alpha_m() const {
  const double r = options_.spectral_radius;
  return (2.0 * r - 1.0) / (r + 1.0);
}
double TimeIntegrator::alpha_f() const { return options_.spectral_radius / (options_.spectral_radius + 1.0); }
double TimeIntegrator::gamma() const { return 0.5 - alpha_m() + alpha_f(); }
double TimeIntegrator::beta() const {
  const double s = 1.0 - alpha_m() + alpha_f();
  return 0.25 * s * s;
}

void TimeIntegrator::set_initial(const Eigen::VectorXd& u, const Eigen::VectorXd& v) {
  u_ = u;
  v_ = v;
  last_dt_ = 0.0;  // a new initial state: nothing to extrapolate
  problem_.commit_interactions(u_);
  const auto assembly = problem_.assemble(u_, options_.dt, false);
  if (!assembly.ok) throw Error("time integration: initial state: " + assembly.reason);
  f_int_ = assembly.internal;
  a_.setZero(u_.size());
  if (options_.scheme == TimeScheme::generalized_alpha) {
    SparseMatrix m = problem_.mass();
    problem_.constrain(m);
    Eigen::VectorXd rhs = problem_.external(0.0) - f_int_;
    problem_.zero_constrained(rhs);
    numerics::LinearSolver mass_solver(numerics::LinearSolverKind::cholesky);
    if (!mass_solver.factorize(m, numerics::MatrixStorage::lower_symmetric)) throw Error("time integration: the mass matrix is singular");
    a_ = mass_solver.solve(rhs);
  }
}

TimeIntegrator::Attempt TimeIntegrator::step(double t0, double dt) {
  trial_.valid = false;
  trial_.newton_iterations = trial_.line_search_reductions = 0;
  Attempt at;
  if (options_.coupled_step) {
    if (!options_.coupled_step(*this, t0, dt, at.reason)) return at;
    if (!trial_.valid || trial_.t0 != t0 || trial_.dt != dt) {
      at.reason = "the coupled step ended without a solved trial of this step";
      return at;
    }
    at.record.newton_iterations = trial_.newton_iterations;
    at.record.line_search_reductions = trial_.line_search_reductions;
    at.record.residual = trial_.residual_norm;
  } else {
    at = solve(t0, dt);
    if (!at.ok) return at;
  }
  accept();
  at.ok = true;
  at.record.time = t0 + dt;
  at.record.dt = dt;
  return at;
}

bool TimeIntegrator::solve_trial(double t0, double dt, std::string& reason) {
  const Attempt at = solve(t0, dt);
  reason = at.reason;
  return at.ok;
}

Eigen::VectorXd TimeIntegrator::trial_v() const {
  if (options_.scheme != TimeScheme::generalized_alpha) return (trial_.u - u_) / trial_.dt;
  return v_ + trial_.dt * ((1.0 - gamma()) * a_ + gamma() * trial_.a);
}

void TimeIntegrator::accept() {
  const bool dynamic = options_.scheme == TimeScheme::generalized_alpha;
  problem_.commit(std::move(trial_.states));
  stresses_ = std::move(trial_.stresses);
  if (dynamic) {
    v_ = trial_v();
    a_ = trial_.a;
  }
  last_increment_ = trial_.u - u_;
  last_dt_ = trial_.dt;
  u_ = trial_.u;
  problem_.commit_interactions(u_);
  f_int_ = trial_.internal;
  reactions_.setZero(u_.size());
  const auto& constrained = problem_.constrained();
  for (Eigen::Index i = 0; i < u_.size(); ++i) {
    if (constrained[static_cast<size_t>(i)]) reactions_(i) = trial_.residual(i);
  }
  trial_.valid = false;
}

Eigen::VectorXd TimeIntegrator::predictor(double t0, double dt) const {
  // The last accepted increment scaled to this step (linear extrapolation, as Abaqus/Standard's
  // default EXTRAPOLATION=LINEAR); on the first step, constant velocity (dynamic) or the last state
  // (quasi-static). In the pressure ramp of the default scene this cut the Newton iterations of the
  // first 60 ns from 910 to 533 against constant velocity (generalized-α's velocity oscillates about
  // the sliding velocity; the increment is what the chip actually did). A repeated trial of the same
  // step (a coupled step) starts from the last trial's solution.
  const bool dynamic = options_.scheme == TimeScheme::generalized_alpha;
  const bool repeat = trial_.valid && trial_.t0 == t0 && trial_.dt == dt;
  Eigen::VectorXd u1 = repeat           ? trial_.u
                       : last_dt_ > 0.0 ? Eigen::VectorXd(u_ + (dt / last_dt_) * last_increment_)
                       : dynamic        ? Eigen::VectorXd(u_ + dt * v_)
                                        : u_;
  problem_.apply_dirichlet(t0 + dt, u1);
  return u1;
}

TimeIntegrator::StepSystem TimeIntegrator::step_system(double t0, double dt) const {
  StepSystem sys;
  sys.dynamic = options_.scheme == TimeScheme::generalized_alpha;
  sys.dt = dt;
  sys.t1 = t0 + dt;
  sys.f_ext1 = problem_.external(sys.t1);
  sys.f_ext0 = problem_.external(t0);
  sys.storage = problem_.tangent_storage();
  sys.symmetry = problem_.tangent_symmetry();
  sys.mass = sys.dynamic ? &problem_.mass() : nullptr;
  sys.tangent_mass = sys.dynamic ? &problem_.mass(sys.storage) : nullptr;
  sys.mass_factor = sys.dynamic ? (1.0 - alpha_m()) / (beta() * dt * dt) : 0.0;
  sys.stiffness_factor = sys.dynamic ? 1.0 - alpha_f() : 1.0;
  return sys;
}

TimeIntegrator::Evaluation TimeIntegrator::evaluate(const StepSystem& sys, const Eigen::VectorXd& u, bool with_tangent,
                                                    const std::vector<MaterialState>* guesses) {
  Evaluation e;
  const auto start = std::chrono::steady_clock::now();
  e.assembly = problem_.assemble(u, sys.dt, with_tangent, guesses);
  report_.seconds_assembly += seconds_since(start);
  report_.seconds_contact += e.assembly.seconds_interactions;
  ++report_.assemblies;
  if (!e.assembly.ok) return e;
  const double dt = sys.dt, am = alpha_m(), af = alpha_f(), b = beta();
  if (sys.dynamic) {
    e.a1 = (u - u_ - dt * v_ - dt * dt * (0.5 - b) * a_) / (b * dt * dt);
    const Eigen::VectorXd inertia = sys.mass->selfadjointView<Eigen::Lower>() * ((1.0 - am) * e.a1 + am * a_);
    e.residual = inertia + (1.0 - af) * e.assembly.internal + af * f_int_ - (1.0 - af) * sys.f_ext1 - af * sys.f_ext0;
    e.scale = std::max({e.assembly.internal.norm(), sys.f_ext1.norm(), inertia.norm()});
  } else {
    e.residual = e.assembly.internal - sys.f_ext1;
    e.scale = std::max(e.assembly.internal.norm(), sys.f_ext1.norm());
  }
  e.norm = free_norm(e.residual, problem_.constrained());
  return e;
}

bool TimeIntegrator::factorize_tangent(const StepSystem& sys, MovableSparseMatrix k, std::string& reason) {
  if (sys.stiffness_factor != 1.0) k *= sys.stiffness_factor;
  if (sys.dynamic) {
    // Same pattern as the tangent: add value arrays.
    Eigen::Map<Eigen::VectorXd>(k.valuePtr(), k.nonZeros()) +=
        sys.mass_factor * Eigen::Map<const Eigen::VectorXd>(sys.tangent_mass->valuePtr(), sys.tangent_mass->nonZeros());
  }
  problem_.constrain(k);
  if (solver_.factorize(k, sys.storage, sys.symmetry)) return true;
  reason = solver_.reason();
  return false;
}

double TimeIntegrator::forcing_term(int iteration, double norm, double previous_norm, double tolerance) {
  // Eisenstat & Walker 1996 (SIAM J. Sci. Comput. 17:16), choice 2: γ (‖G_k‖/‖G_{k−1}‖)², capped,
  // and never asking the Krylov solve for more than half the Newton tolerance.
  double forcing = kMaxForcing;
  if (iteration > 0 && previous_norm > 0.0) forcing = std::min(kMaxForcing, kForcingGamma * std::pow(norm / previous_norm, 2));
  return std::min(std::max(forcing, 0.5 * tolerance / norm), kMaxForcing);
}

TimeIntegrator::LineSearch TimeIntegrator::line_search(const StepSystem& sys, const Eigen::VectorXd& u,
                                                       const Eigen::VectorXd& delta, double norm, bool with_tangent,
                                                       const std::vector<MaterialState>* guesses, StepRecord& record) {
  // Backtracking on φ(s) = ‖G(u + sδ)‖², φ'(0) = −2φ(0) for a Newton direction, with the quadratic
  // model's minimiser kept in [0.1 s, 0.5 s] (Dennis & Schnabel 1983, Algorithm A6.3.1).
  // Trials are evaluated with their tangent: the accepted one is the next iteration's
  // linearisation. Most trials are accepted (the full step usually, and the last of a line search
  // always); evaluating line-search trials without a tangent and the accepted point again with one
  // cost more (128 x 24 default scene: 199 reduced trials, 155 of them accepted).
  const double phi0 = norm * norm;
  LineSearch ls{evaluate(sys, u + delta, with_tangent, guesses), 1.0, with_tangent};
  if (!options_.line_search) return ls;
  for (int r = 0; r < kLineSearchMaxReductions; ++r) {
    const double phi1 = ls.trial.assembly.ok ? ls.trial.norm * ls.trial.norm : std::numeric_limits<double>::infinity();
    if (phi1 <= (1.0 - 2.0 * kLineSearchSufficientDecrease * ls.step) * phi0) break;
    const double s = ls.step;
    const double minimiser = std::isfinite(phi1) ? phi0 * s * s / (phi1 - phi0 + 2.0 * phi0 * s) : 0.1 * s;
    ls.step = std::clamp(minimiser, 0.1 * s, 0.5 * s);
    ls.trial = evaluate(sys, u + ls.step * delta, true, guesses);
    ls.has_tangent = true;
    ++record.line_search_reductions;
  }
  return ls;
}

void TimeIntegrator::keep_trial(double t0, double dt, Eigen::VectorXd u1, Evaluation&& solved, const StepRecord& record) {
  trial_.t0 = t0;
  trial_.dt = dt;
  trial_.valid = true;
  trial_.u = std::move(u1);
  trial_.a = std::move(solved.a1);
  trial_.internal = std::move(solved.assembly.internal);
  trial_.residual = std::move(solved.residual);
  trial_.states = std::move(solved.assembly.states);
  trial_.stresses = std::move(solved.assembly.stresses);
  trial_.newton_iterations += record.newton_iterations;
  trial_.last_newton_iterations = record.newton_iterations;
  trial_.line_search_reductions += record.line_search_reductions;
  trial_.residual_norm = record.residual;
}

TimeIntegrator::Attempt TimeIntegrator::solve(double t0, double dt) {
  Attempt at;
  Eigen::VectorXd u1 = predictor(t0, dt);
  const StepSystem sys = step_system(t0, dt);
  // The material states of the last evaluation in this step: first guesses for the next one's
  // return maps (a Johnson-Cook update then needs fewer of its own Newton iterations).
  const std::vector<MaterialState>* last_states = nullptr;
  Evaluation current = evaluate(sys, u1, true, last_states);
  last_states = &current.assembly.states;  // `current` is reassigned in place: the pointer stays valid
  double force_scale = 0.0;
  const auto tolerance_at = [&](double scale) { return options_.relative_tolerance * scale + 1e-300; };
  bool factorized = false, last_full_step = false;
  double previous_norm = 0.0;
  for (int it = 0;; ++it) {
    if (!current.assembly.ok) {
      at.reason = current.assembly.reason;
      return at;
    }
    if (!std::isfinite(current.norm)) {
      at.reason = "the residual is not finite";
      return at;
    }
    force_scale = std::max(force_scale, current.scale);
    const double tolerance = tolerance_at(force_scale);
    if (trace_newton()) {
      std::fprintf(stderr, "newton t %.4g dt %.3g it %d residual %.6e tolerance %.3e\n", sys.t1, dt, it, current.norm, tolerance);
    }
    at.record.residual = current.norm;
    at.record.newton_iterations = it;
    if (current.norm <= tolerance) break;
    if (it >= options_.max_newton_iterations) {
      at.reason = "Newton did not converge in " + std::to_string(it) + " iterations (residual " +
                  std::to_string(current.norm) + " N, tolerance " + std::to_string(tolerance) + " N)";
      return at;
    }
    Eigen::VectorXd rhs = -current.residual;
    problem_.zero_constrained(rhs);
    const auto start = std::chrono::steady_clock::now();
    // In the quadratic phase the tangent hardly changes between iterations: the last factorisation
    // serves once more (a chord step), and any sign of trouble brings a fresh one.
    const bool reuse = solver_.factorizes_by_lu(sys.symmetry) && factorized && last_full_step &&
                       current.norm < kReuseFactorizationBelow * previous_norm;
    if (!reuse) {
      if (!factorize_tangent(sys, std::move(current.assembly.tangent), at.reason)) return at;
      factorized = true;
    }
    // In the quadratic phase, e_{k+1} ≈ C e_k² with C ≈ e_k / e_{k−1}² predicts whether the full step
    // lands within tolerance; if it does, the tangent there would go unused, and the trial is
    // evaluated without one (a wrong guess costs one more evaluation of the same point).
    const bool expect_convergence = it > 0 && last_full_step && current.norm < 0.1 * previous_norm &&
                                    std::pow(current.norm / previous_norm, 2) * current.norm <
                                        kPredictedConvergenceMargin * tolerance;
    const double forcing = forcing_term(it, current.norm, previous_norm, tolerance);
    previous_norm = current.norm;
    const Eigen::VectorXd delta = solver_.solve(rhs, forcing);
    report_.seconds_solve += seconds_since(start);
    LineSearch ls = line_search(sys, u1, delta, current.norm, !expect_convergence, last_states, at.record);
    if (trace_newton()) std::fprintf(stderr, "newton   step length %.3g after %d reductions\n", ls.step, at.record.line_search_reductions);
    u1 += ls.step * delta;
    const bool stagnated = ls.step * delta.norm() <= kNewtonStagnationIncrement * std::max(u1.norm(), 1e-300) &&
                           ls.trial.norm <= 1e3 * tolerance;
    last_full_step = ls.step == 1.0;
    const double next_tolerance = tolerance_at(std::max(force_scale, ls.trial.scale));
    if (ls.has_tangent || stagnated || !ls.trial.assembly.ok || ls.trial.norm <= next_tolerance) {
      current = std::move(ls.trial);  // evaluated at the new u1 (with its tangent unless it will not be needed)
    } else {
      // The prediction failed: the same point with its tangent, the trial's states as exact guesses.
      last_states = &ls.trial.assembly.states;
      current = evaluate(sys, u1, true, last_states);
      last_states = &current.assembly.states;
      ++report_.unpredicted_convergence;
    }
    if (stagnated && current.assembly.ok) {
      at.record.newton_iterations = it + 1;
      at.record.residual = current.norm;
      break;
    }
  }
  keep_trial(t0, dt, std::move(u1), std::move(current), at.record);
  at.ok = true;
  at.record.time = sys.t1;
  at.record.dt = dt;
  return at;
}

double TimeIntegrator::next_step(double t, double dt, int newton_iterations) const {
  const double max_dt = options_.max_dt_at ? options_.max_dt_at(t)
                        : options_.max_dt > 0.0 ? std::max(options_.max_dt, options_.dt)
                                                : options_.dt;
  const double factor = std::clamp(static_cast<double>(kTargetNewtonIterations) / std::max(newton_iterations, 1),
                                   kMaxStepShrink, kMaxStepGrowth);
  // never grow a cut-back step by shrinking; a phase may ask for steps shorter than that floor
  const double shortest = std::min({dt, kShortestControlledStep * options_.dt, max_dt});
  return std::clamp(factor * dt, shortest, max_dt);
}

void TimeIntegrator::record_solver_counts() {
  report_.symbolic_analyses = solver_.analyses();
  report_.lu_fallbacks = solver_.lu_fallbacks();
  report_.krylov_iterations = solver_.krylov_iterations();
}

IntegrationReport TimeIntegrator::run(const std::function<void(const StepView&)>& on_step) {
  // The sparse factorisations' dense blocks are small: OpenBLAS threads would only spin.
  const SingleThreadedBlas single_threaded_blas;
  report_ = IntegrationReport();
  double t = 0.0, dt = options_.dt;
  int consecutive_cuts = 0;
  const double end_tolerance = 1e-12 * options_.end_time;
  while (t < options_.end_time - end_tolerance) {
    const double this_dt = std::min(dt, options_.end_time - t);
    const std::vector<MaterialState> saved_states = problem_.states();
    const Attempt at = step(t, this_dt);
    if (!at.ok) {
      problem_.commit(saved_states);
      report_.cutbacks.push_back({t, this_dt, at.reason});
      if (std::string stop_reason; options_.should_stop && options_.should_stop(stop_reason)) {
        record_solver_counts();
        report_.reason = "stopped after a failed step at " + time_label(t) + ": " + stop_reason;
        return report_;
      }
      if (++consecutive_cuts > options_.max_cutbacks) {
        record_solver_counts();
        report_.reason = "step at " + time_label(t) + " failed after " + std::to_string(options_.max_cutbacks) +
                         " cut-backs: " + at.reason;
        return report_;
      }
      dt = 0.5 * this_dt;
      continue;
    }
    consecutive_cuts = 0;
    t += this_dt;
    report_.steps.push_back(at.record);
    report_.newton_iterations += at.record.newton_iterations;
    report_.line_search_reductions += at.record.line_search_reductions;
    if (options_.after_step) {
      std::string reason;
      const auto start = std::chrono::steady_clock::now();
      const bool ok = options_.after_step(t, this_dt, u_, reason);
      report_.seconds_after_step += seconds_since(start);
      if (!ok) {
        record_solver_counts();
        report_.reason = "after the step to " + time_label(t) + ": " + reason;
        return report_;
      }
    }
    if (on_step) on_step(StepView{t, u_, v_, a_, reactions_, stresses_, problem_});
    // A coupled step's record sums the Newton iterations of its trials; the step size follows the
    // last trial's, the one that measures how hard this step length is for the chip.
    dt = next_step(t, this_dt, options_.coupled_step ? trial_.last_newton_iterations : at.record.newton_iterations);
  }
  report_.completed = true;
  record_solver_counts();
  return report_;
}

}  // namespace mufric::solid
