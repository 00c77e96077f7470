#pragma once
// The one interface every friction law implements (GP, empirical MLR, Coulomb), so the server,
// the client and the CLI never care which kind of model answers.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "common/h5_file.hpp"
#include "common/input_space.hpp"

namespace mufric {

// The rows a model evaluates as one block, from a batch's first (the GP's blocked products). σ's last
// bits may depend on how a query falls into blocks (a GP's short last block takes a row-by-row path),
// μ's never: whoever splits a batch into calls cuts at multiples of this so that σ keeps its bits.
inline constexpr long long kEvaluationBlockRows = 128;

// extrapolated: outside the training box, answered under the raw or clamp policy; out_of_box: outside
// it under the refuse policy, NaN outputs.
enum class PointStatus : std::uint8_t { ok = 0, extrapolated = 1, invalid_input = 2, out_of_box = 3 };
std::string_view to_string(PointStatus status);
// Whether a point got no μ: its input was invalid, or it lay outside the box under the refuse policy.
constexpr bool has_no_answer(PointStatus status) {
  return status == PointStatus::invalid_input || status == PointStatus::out_of_box;
}

// What a model does with a point outside its training box.
//   raw     the model itself, far from its data (a GP reverts to its prior mean, with a wide band)
//   clamp   μ of the model at the nearest point of the box (each input clamped to its range; the
//           gradient along a clamped input is zero), still flagged EXTRAPOLATED — seed 001's way; σ is
//           the model's root-mean-square error of that μ at the real point, √(σ²(x) + (μ(x) − μ_face)²),
//           so the interval grows with the distance from the box
//   refuse  no answer: status OUT_OF_BOX, NaN outputs
enum class Extrapolation : std::uint8_t { model_default = 0, raw = 1, clamp = 2, refuse = 3 };
std::string_view to_string(Extrapolation policy);
// "raw", "clamp" or "refuse"; throws mufric::Error naming the word otherwise.
Extrapolation extrapolation_from_string(std::string_view word);
// The policy a request is answered by: its own, or the model's when it asks for the model's default.
inline Extrapolation effective_extrapolation(Extrapolation requested, Extrapolation model_default) {
  return requested == Extrapolation::model_default ? model_default : requested;
}

// What the caller needs; nothing more is computed.
struct EvaluationRequest {
  bool std = false;         // predictive standard deviation
  double ci_level = 0.0;    // 0: no interval; else two-sided level in (0, 1), e.g. 0.95
  bool gradient = false;    // dμ/dinput, SI
  // The patch scatter: the per-draw standard deviation of μ about its mean, how much one contact
  // patch's μ varies from another's at the same (p, v, T) (a model trained on independent draws).
  bool patch_std = false;
  // Threads this evaluation may use; 0: as many as OpenMP allows. Never more than 1 inside a
  // parallel region of the caller (evaluation_team_size).
  int max_threads = 0;
  // A model's certified fast evaluator (FastEvaluator) answers only where its measured error bound
  // is within these; 0 (either): the exact model answers everywhere.
  double mu_tolerance = 1e-6;             // absolute, μ units
  double std_relative_tolerance = 1e-3;   // of σ, i.e. of the interval's half-width
  // Points outside the training box: model_default is the policy the model file declares.
  Extrapolation extrapolation = Extrapolation::model_default;

  // Either tolerance 0: the exact model only, no fast evaluator anywhere.
  bool exact_only() const { return mu_tolerance <= 0.0 || std_relative_tolerance <= 0.0; }
};

// A batch of query points, structure-of-arrays: column j of an m × d column-major matrix is the
// packed array of input j, exactly as it arrives on the wire.
using QueryBatch = Eigen::MatrixXd;

struct Evaluation {
  Eigen::VectorXd mu;             // m
  Eigen::VectorXd std;            // m, or empty
  Eigen::VectorXd lo, hi;         // m each, or empty
  Eigen::MatrixXd gradient;       // m × d, or empty
  // m, when asked and the model has a patch scatter (else empty); NaN where μ is NaN. Outside the
  // box it is the nearest face's, under every policy that answers.
  Eigen::VectorXd patch_std;
  std::vector<PointStatus> status;  // m
  long long clamped_variances = 0;  // negative predictive variances clamped to zero
  long long fast_points = 0;        // points answered by the fast evaluator (the rest: the exact model)
  long long range_clipped = 0;      // points whose μ (or interval) was clipped to the model's μ range
};

// What a trained model knows of its training, for `describe` and the service's DescribeModel; a law
// has none (FrictionModel::kind_description).
struct TrainingDescription {
  long long training_points = 0;
  double loo_mean_relative_error = 0.0, loo_max_relative_error = 0.0, loo_coverage_95 = 0.0;
  std::string interval;          // what the interval means, by name: new-run, shared-scatter, mean-over-draws, calibrated
  std::string interval_meaning;  // the same in words
  double micro_std_error = 0.0;  // the shared scatter added to every interval (0: none)
};

// What a calibrated model was calibrated on and its interval's parts at the box centre (μ units), for
// `describe` and DescribeModel; see surrogate/calibration/calibrated_model.hpp.
// A calibrated model's interval at a point, in its parts (μ units): sd² = parameter_sd² +
// conditional_sd²; emulator_sd and discrepancy_sd are η's and δ's alone given the data, which need
// not add up (given the measurements η and δ are correlated: what one explains the other need not).
struct IntervalParts {
  double mu = 0.0, sd = 0.0, parameter_sd = 0.0, conditional_sd = 0.0, emulator_sd = 0.0, discrepancy_sd = 0.0;
};

struct CalibrationDescription {
  struct Parameter {
    std::string name;
    double mean = 0.0, sd = 0.0, lo95 = 0.0, hi95 = 0.0;
  };
  std::string data_source;
  long long measurements = 0, posterior_samples = 0;
  bool discrepancy = false;
  std::vector<Parameter> parameters;
  IntervalParts at_box_centre;
};

// The structured description of a kind: the parts it has.
struct KindDescription {
  std::optional<TrainingDescription> training;
  std::optional<CalibrationDescription> calibration;
};

class FrictionModel {
 public:
  virtual ~FrictionModel() = default;
  virtual std::string_view kind() const = 0;  // "gp", "mlr", "coulomb"
  const InputSpace& inputs() const { return inputs_; }
  // Whether std/CI carry information (a GP) or are identically zero (a deterministic law).
  virtual bool has_uncertainty() const = 0;
  // Whether the model serves a patch scatter (EvaluationRequest::patch_std).
  virtual bool has_patch_scatter() const { return false; }

  // The policy for points outside the box when a request does not choose one; and the physical
  // range μ is kept in (μ, lo and hi are clipped to it): both declared by the model file.
  static constexpr Extrapolation kDefaultExtrapolation = Extrapolation::clamp;
  static constexpr double kDefaultMuMin = 0.0, kDefaultMuMax = 1.0;
  Extrapolation default_extrapolation() const { return default_extrapolation_; }
  void set_default_extrapolation(Extrapolation policy);
  double mu_min() const { return mu_min_; }
  double mu_max() const { return mu_max_; }
  void set_mu_range(double lo, double hi);  // throws mufric::Error unless finite with lo < hi

  // Validates each point (non-finite, negative pressure/velocity/temperature → INVALID_INPUT with
  // NaN outputs; outside the training box → the extrapolation policy) and evaluates the rest; μ and
  // the interval are then clipped to the model's μ range.
  Evaluation evaluate(const QueryBatch& x, const EvaluationRequest& what) const;

  // Writes the kind-specific groups; the common header is written by save_model().
  virtual void write(h5::Writer& out) const = 0;

  // Free text: provenance, accuracy figures (shown by describe/train).
  virtual std::string summary() const = 0;
  // What the kind can say of itself beyond the summary, structured (describe, DescribeModel, the
  // clients' ModelInfo): a law nothing, a trained model its training, a calibrated one its calibration.
  virtual KindDescription kind_description() const { return {}; }

 protected:
  explicit FrictionModel(InputSpace inputs) : inputs_(std::move(inputs)) {}
  // Evaluates valid points only (x has no invalid rows); fills mu and whatever `what` asks for.
  // std is filled when what.std or what.ci_level > 0.
  virtual void evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const = 0;
  // The patch scatter at valid points (only called when has_patch_scatter()).
  virtual Eigen::VectorXd patch_std_valid(const QueryBatch& x, const EvaluationRequest& what) const;

 private:
  // σ of the clamped answers (rows of `clamped`, evaluated at the box face) of points outside the box.
  void widen_clamped_intervals(const QueryBatch& x, const std::vector<Eigen::Index>& valid, const EvaluationRequest& what,
                               Evaluation& clamped) const;

  InputSpace inputs_;
  Extrapolation default_extrapolation_ = kDefaultExtrapolation;
  double mu_min_ = kDefaultMuMin, mu_max_ = kDefaultMuMax;
};

// Why a point (SI, one value per input) is INVALID_INPUT, OUT_OF_BOX or EXTRAPOLATED, naming the
// input and the side, in human units: "contact_pressure: -5MPa is below 0MPa, the least a pressure
// can be", "contact_pressure: 10000MPa is above the box (300MPa to 1300MPa)"; "" for a point inside.
std::string point_reason(const InputSpace& inputs, const double* x);
// One line for a response: the first point that got no answer (INVALID_INPUT, OUT_OF_BOX) and why,
// with how many more there are; "" when every point was answered. x: the batch, one row per point.
// " (and 2 more points without an answer)", " (and 1 more point outside the box)": how a block's
// message counts the points after the first it names; "" when there are none.
std::string more_points_tail(long long more, bool extrapolated);
std::string unanswered_points_message(const InputSpace& inputs, const QueryBatch& x, const std::vector<PointStatus>& status);
// When every point was answered but some lie outside the box: the first such point, which input and
// how it was answered under `policy` (clamp: at the box's nearest point; raw: the model beyond its
// data), and how many more, e.g. "point 0 EXTRAPOLATED: contact_pressure: 2500MPa is above the box
// (300MPa to 2000MPa); answered at contact_pressure = 2000MPa (clamp)". "" when none is outside.
std::string extrapolated_points_message(const InputSpace& inputs, const QueryBatch& x, const std::vector<PointStatus>& status,
                                        Extrapolation policy);
// Where the clamp policy answers a point x outside the box: "contact_pressure = 2000MPa", each
// clamped input outside the box at its nearest face (angles are periodic, never clamped).
std::string clamped_face_text(const InputSpace& inputs, const double* x);
// A block's message, the same in the server's reply and the in-process Answer: its first point
// without an answer (unanswered_points_message), else its first point outside the box
// (extrapolated_points_message), else "".
std::string block_message(const InputSpace& inputs, const QueryBatch& x, const std::vector<PointStatus>& status,
                          Extrapolation policy);

// Two-sided normal quantile z such that P(|Z| ≤ z) = level (Boost.Math).
double normal_quantile_two_sided(double level);

}  // namespace mufric
