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

TimeIntegrator::Attempt TimeIntegrator::solve(double t0, double dt) {
  Attempt at;
  const bool dynamic = options_.scheme == TimeScheme::generalized_alpha;
  const double am = alpha_m(), af = alpha_f(), b = beta();
  const double t1 = t0 + dt;
  const auto& constrained = problem_.constrained();
  // Predictor: the last accepted increment scaled to this step (linear extrapolation, as
  // Abaqus/Standard's default EXTRAPOLATION=LINEAR); on the first step, constant velocity (dynamic)
  // or the last state (quasi-static). In the pressure ramp of the default scene this cut the Newton
  // iterations of the first 60 ns from 910 to 533 against constant velocity (generalized-α's
  // velocity oscillates about the sliding velocity; the increment is what the chip actually did).
  // A repeated trial of the same step (a coupled step) starts from the last trial's solution.
  const bool repeat = trial_.valid && trial_.t0 == t0 && trial_.dt == dt;
  Eigen::VectorXd u1 = repeat           ? trial_.u
                       : last_dt_ > 0.0 ? Eigen::VectorXd(u_ + (dt / last_dt_) * last_increment_)
                       : dynamic        ? Eigen::VectorXd(u_ + dt * v_)
                                        : u_;
  problem_.apply_dirichlet(t1, u1);
  const Eigen::VectorXd f_ext1 = problem_.external(t1), f_ext0 = problem_.external(t0);
  const numerics::MatrixStorage storage = problem_.tangent_storage();
  const numerics::Symmetry symmetry = problem_.tangent_symmetry();
  const SparseMatrix* mass = dynamic ? &problem_.mass() : nullptr;
  const SparseMatrix* tangent_mass = dynamic ? &problem_.mass(storage) : nullptr;
  const double mass_factor = dynamic ? (1.0 - am) / (b * dt * dt) : 0.0;
  const double stiffness_factor = dynamic ? 1.0 - af : 1.0;

  // The residual G(u1) and the quantities that come with it.
  struct Evaluation {
    SolidProblem::Assembly assembly;
    Eigen::VectorXd residual, a1;
    double norm = 0.0, scale = 0.0;
  };
  // The material states of the last evaluation in this step: first guesses for the next one's
  // return maps (a Johnson-Cook update then needs fewer of its own Newton iterations).
  const std::vector<MaterialState>* last_states = nullptr;
  auto evaluate = [&](const Eigen::VectorXd& u, bool with_tangent) {
    Evaluation e;
    const auto start = std::chrono::steady_clock::now();
    e.assembly = problem_.assemble(u, dt, with_tangent, last_states);
    report_.seconds_assembly += seconds_since(start);
    report_.seconds_contact += e.assembly.seconds_interactions;
    ++report_.assemblies;
    if (!e.assembly.ok) return e;
    if (dynamic) {
      e.a1 = (u - u_ - dt * v_ - dt * dt * (0.5 - b) * a_) / (b * dt * dt);
      const Eigen::VectorXd inertia = mass->selfadjointView<Eigen::Lower>() * ((1.0 - am) * e.a1 + am * a_);
      e.residual = inertia + (1.0 - af) * e.assembly.internal + af * f_int_ - (1.0 - af) * f_ext1 - af * f_ext0;
      e.scale = std::max({e.assembly.internal.norm(), f_ext1.norm(), inertia.norm()});
    } else {
      e.residual = e.assembly.internal - f_ext1;
      e.scale = std::max(e.assembly.internal.norm(), f_ext1.norm());
    }
    e.norm = free_norm(e.residual, constrained);
    return e;
  };

  Evaluation current = evaluate(u1, true);
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
      std::fprintf(stderr, "newton t %.4g dt %.3g it %d residual %.6e tolerance %.3e\n", t1, dt, it, current.norm, tolerance);
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
    const bool reuse = solver_.factorizes_by_lu(symmetry) && factorized && last_full_step &&
                       current.norm < kReuseFactorizationBelow * previous_norm;
    if (!reuse) {
      MovableSparseMatrix k = std::move(current.assembly.tangent);
      if (stiffness_factor != 1.0) k *= stiffness_factor;
      if (dynamic) {
        // Same pattern as the tangent: add value arrays.
        Eigen::Map<Eigen::VectorXd>(k.valuePtr(), k.nonZeros()) +=
            mass_factor * Eigen::Map<const Eigen::VectorXd>(tangent_mass->valuePtr(), tangent_mass->nonZeros());
      }
      problem_.constrain(k);
      if (!solver_.factorize(k, storage, symmetry)) {
        at.reason = solver_.reason();
        return at;
      }
      factorized = true;
    }
    // In the quadratic phase, e_{k+1} ≈ C e_k² with C ≈ e_k / e_{k−1}² predicts whether the full step
    // lands within tolerance; if it does, the tangent there would go unused, and the trial is
    // evaluated without one (a wrong guess costs one more evaluation of the same point).
    const bool expect_convergence = it > 0 && last_full_step && current.norm < 0.1 * previous_norm &&
                                    std::pow(current.norm / previous_norm, 2) * current.norm <
                                        kPredictedConvergenceMargin * tolerance;
    double forcing = kMaxForcing;
    if (it > 0 && previous_norm > 0.0) forcing = std::min(kMaxForcing, kForcingGamma * std::pow(current.norm / previous_norm, 2));
    forcing = std::max(forcing, 0.5 * tolerance / current.norm);
    previous_norm = current.norm;
    const Eigen::VectorXd delta = solver_.solve(rhs, std::min(forcing, kMaxForcing));
    report_.seconds_solve += seconds_since(start);
    // Line search on φ(s) = ‖G(u + sδ)‖², φ'(0) = −2φ(0) for a Newton direction.
    const double phi0 = current.norm * current.norm;
    double s = 1.0;
    // Trials are evaluated with their tangent: the accepted one is the next iteration's
    // linearisation. Most trials are accepted (the full step usually, and the last of a line search
    // always); evaluating line-search trials without a tangent and the accepted point again with one
    // cost more (128 x 24 default scene: 199 reduced trials, 155 of them accepted).
    Evaluation trial = evaluate(u1 + delta, !expect_convergence);
    bool trial_has_tangent = !expect_convergence;
    if (options_.line_search) {
      for (int r = 0; r < kLineSearchMaxReductions; ++r) {
        const double phi1 = trial.assembly.ok ? trial.norm * trial.norm : std::numeric_limits<double>::infinity();
        if (phi1 <= (1.0 - 2.0 * kLineSearchSufficientDecrease * s) * phi0) break;
        const double minimiser = std::isfinite(phi1) ? phi0 * s * s / (phi1 - phi0 + 2.0 * phi0 * s) : 0.1 * s;
        s = std::clamp(minimiser, 0.1 * s, 0.5 * s);
        trial = evaluate(u1 + s * delta, true);
        trial_has_tangent = true;
        ++at.record.line_search_reductions;
      }
    }
    if (trace_newton()) std::fprintf(stderr, "newton   step length %.3g after %d reductions\n", s, at.record.line_search_reductions);
    u1 += s * delta;
    const bool stagnated = s * delta.norm() <= kNewtonStagnationIncrement * std::max(u1.norm(), 1e-300) &&
                           trial.norm <= 1e3 * tolerance;
    last_full_step = s == 1.0;
    const double next_tolerance = tolerance_at(std::max(force_scale, trial.scale));
    if (trial_has_tangent || stagnated || !trial.assembly.ok || trial.norm <= next_tolerance) {
      current = std::move(trial);  // evaluated at the new u1 (with its tangent unless it will not be needed)
    } else {
      // The prediction failed: the same point with its tangent, the trial's states as exact guesses.
      last_states = &trial.assembly.states;
      current = evaluate(u1, true);
      last_states = &current.assembly.states;
      ++report_.unpredicted_convergence;
    }
    if (stagnated && current.assembly.ok) {
      at.record.newton_iterations = it + 1;
      at.record.residual = current.norm;
      break;
    }
  }
  // The solved trial, accepted by accept().
  trial_.t0 = t0;
  trial_.dt = dt;
  trial_.valid = true;
  trial_.u = std::move(u1);
  trial_.a = std::move(current.a1);
  trial_.internal = std::move(current.assembly.internal);
  trial_.residual = std::move(current.residual);
  trial_.states = std::move(current.assembly.states);
  trial_.stresses = std::move(current.assembly.stresses);
  trial_.newton_iterations += at.record.newton_iterations;
  trial_.last_newton_iterations = at.record.newton_iterations;
  trial_.line_search_reductions += at.record.line_search_reductions;
  trial_.residual_norm = at.record.residual;
  at.ok = true;
  at.record.time = t1;
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
