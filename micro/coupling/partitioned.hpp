#pragma once
// Partitioned, strongly coupled fluid–structure time steps (seed 000 sec. 2.3.1). Per step and
// iteration, the structure turns the interface load λ into an interface displacement d, and the
// fluid, given d (its interface velocity) and λ (the previous interface traction of a Robin condition,
// Make et al., Comput. Math. Appl. 114, 2022), returns a new load λ̃. The fixed point is taken on the
// load, λ ← λ̃(λ), because the Robin condition's traction is then the iterate itself and not a hidden
// state: an accelerator working on d alone while the Robin traction changes underneath it diverged on
// the enclosed pocket. The iteration is accelerated by constant relaxation, Aitken's dynamic
// relaxation (Küttler & Wall, Comput. Mech. 43, 2008) or interface quasi-Newton with an inverse
// Jacobian from a least-squares model (IQN-ILS; Degroote, Bathe & Vierendeels, Comput. Struct. 87,
// 2009) that reuses the secant pairs of past steps and drops near-dependent ones with a QR filter
// (Haelterman et al., Comput. Struct. 171, 2016). Which condition the fluid takes at the interface
// (Dirichlet or Robin) is its own business; the step converges when both the load and the
// displacement stop changing.
#include <deque>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace mufric::coupling {

enum class Acceleration { constant_relaxation, aitken, iqn_ils };

struct CouplingOptions {
  Acceleration acceleration = Acceleration::iqn_ils;
  double relaxation = 0.5;      // ω: constant relaxation, and the first iteration of Aitken and IQN-ILS
  int reuse_steps = 8;          // IQN-ILS: past steps whose secant pairs are kept
  double qr_filter = 1e-8;      // IQN-ILS: a pair keeping less of its norm than this, after the newer ones, is dropped
  double relative_tolerance = 1e-8;       // of |λ̃| for the load, of the step's motion |d − d_start| for the displacement
  // Pa: |λ̃ − λ| / √n (its root mean square over the n components) below this, plus the relative
  // part, is converged. A film beside contact spots carries a small share of the load: its traction
  // measured against itself asks for more than the chip's forces can show (the scene sets this from
  // lubricant.traction_tolerance and the applied pressure).
  double load_tolerance = 1e-3;
  double displacement_tolerance = 1e-15;  // m: |d_k − d_(k−1)| below this (plus the relative part) is converged
  double kinematic_tolerance = 1e-4;      // of the solvers' kinematic residual, when they report one
  int max_iterations = 50;
  // A step fails once this many exchanges in a row have not brought |λ̃ − λ| below its best of the
  // step (0: never): such a step was, on the coarse study point, a step that went on to fail —
  // mostly in a chip solve that spent its 30 Newton iterations first — and its cut-back retry is
  // cheaper than the rest of it.
  int stall_iterations = 0;
  // A solver that fails on an accelerated iterate restarts the step's iteration this many times
  // (from the last iterate both solvers took, with plain relaxation) before the step fails.
  int max_restarts = 0;
};

// The interface fixed-point accelerator; keeps what it learns from one time step to the next.
class InterfaceAccelerator {
 public:
  explicit InterfaceAccelerator(CouplingOptions options);
  void begin_step();
  // The next iterate from the iterate x and its image x̃.
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde);
  void end_step();  // a converged step: its secant pairs join the reuse store
  // Starts the step's iteration over with this relaxation (for the rest of the step) and without any
  // secant pairs, the past steps' included: they led the iteration where a solver failed.
  void restart_step(double relaxation);
  // Drops the past steps' pairs: the map they sampled is not this step's (another step length).
  void forget_past_steps() { reused_.clear(); }
  int columns_used() const { return columns_used_; }  // IQN-ILS: secant pairs in the last update

 private:
  CouplingOptions options_;
  // This step's iterates (residual r = x̃ − x and x̃), for the secant differences.
  std::vector<Eigen::VectorXd> residuals_, outputs_;
  // Past steps' secant pairs: columns ΔR (residual differences) and ΔX̃ (output differences).
  std::deque<std::pair<Eigen::MatrixXd, Eigen::MatrixXd>> reused_;
  double relaxation_ = 0.0;  // this step's: options_.relaxation unless restarted
  double aitken_omega_ = 0.0;
  int columns_used_ = 0;
};

// The two solvers of one time step. structure: interface load → interface displacement; fluid:
// interface displacement and the current load (for a Robin condition) → new interface load. Both
// return false with a reason when they fail.
struct PartitionedSolvers {
  std::function<bool(const Eigen::VectorXd& load, Eigen::VectorXd& displacement, std::string& reason)> structure;
  std::function<bool(const Eigen::VectorXd& displacement, const Eigen::VectorXd& load, Eigen::VectorXd& new_load,
                     std::string& reason)> fluid;
  // Optional: how far the fluid's interface velocity is from the structure's after the last fluid
  // solve, as a dimensionless measure (a Robin condition meets the velocities only at the fixed
  // point: v − g = (λ − λ̃)/α). Checked against kinematic_tolerance besides load and displacement.
  std::function<double()> kinematic_residual;
  // Optional: per load component, how much of it reaches the structure (in [0, 1]; empty: all). The
  // load's convergence is measured on the part that does (a film's traction over a contact spot, which
  // the contact carries instead, is the fluid's own business, checked by its kinematic residual).
  std::function<Eigen::VectorXd()> load_share;
};

struct CouplingStepReport {
  bool converged = false;
  std::string reason;
  int iterations = 0;                      // structure–fluid exchanges
  int restarts = 0;                        // restarts after a solver failed on an accelerated iterate
  std::vector<double> load_residuals;      // |λ̃ − λ| per iteration
  std::vector<double> displacement_changes;  // |d_k − d_(k−1)| per iteration (d_(−1): the predictor)
  std::vector<double> kinematic_residuals;   // per iteration, when the solvers report one
};

// One coupled step. load: the last step's interface load on entry (sized; zeros for a first step),
// the converged load on return; displacement: the predictor on entry, the converged interface
// displacement on return. Both are left as on entry when the step does not converge.
CouplingStepReport coupled_step(const PartitionedSolvers& solvers, Eigen::VectorXd& load, Eigen::VectorXd& displacement,
                                InterfaceAccelerator& accelerator, const CouplingOptions& options);

// Every reason coupled_step gives when the interface iteration itself fails (it runs out of
// exchanges, stalls or diverges) begins with this; a solver failing inside it does not. Callers that
// explain a stop (e.g. scene::explain_stop: a sealed pocket stalls the iteration) recognise it with
// is_interface_failure, anywhere in a reason that later layers have prefixed, so the wording lives here.
inline constexpr std::string_view kInterfaceIterationFailed = "the interface iteration";
bool is_interface_failure(std::string_view reason);

}  // namespace mufric::coupling
