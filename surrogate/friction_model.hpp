#pragma once
// The one interface every friction law implements (GP, empirical MLR, Coulomb), so the server,
// the client and the CLI never care which kind of model answers.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "common/h5_file.hpp"
#include "common/input_space.hpp"

namespace mufric {

enum class PointStatus : std::uint8_t { ok = 0, extrapolated = 1, invalid_input = 2 };
std::string_view to_string(PointStatus status);

// What the caller needs; nothing more is computed.
struct EvaluationRequest {
  bool std = false;         // predictive standard deviation
  double ci_level = 0.0;    // 0: no interval; else two-sided level in (0, 1), e.g. 0.95
  bool gradient = false;    // dμ/dinput, SI
  // Threads this evaluation may use; 0: as many as OpenMP allows. Never more than 1 inside a
  // parallel region of the caller (evaluation_team_size).
  int max_threads = 0;
  // A model's certified fast evaluator (FastEvaluator) answers only where its measured error bound
  // is within these; 0 (either): the exact model answers everywhere.
  double mu_tolerance = 1e-6;             // absolute, μ units
  double std_relative_tolerance = 1e-3;   // of σ, i.e. of the interval's half-width
};

// A batch of query points, structure-of-arrays: column j of an m × d column-major matrix is the
// packed array of input j, exactly as it arrives on the wire.
using QueryBatch = Eigen::MatrixXd;

struct Evaluation {
  Eigen::VectorXd mu;             // m
  Eigen::VectorXd std;            // m, or empty
  Eigen::VectorXd lo, hi;         // m each, or empty
  Eigen::MatrixXd gradient;       // m × d, or empty
  std::vector<PointStatus> status;  // m
  long long clamped_variances = 0;  // negative predictive variances clamped to zero
  long long fast_points = 0;        // points answered by the fast evaluator (the rest: the exact model)
};

class FrictionModel {
 public:
  virtual ~FrictionModel() = default;
  virtual std::string_view kind() const = 0;  // "gp", "mlr", "coulomb"
  const InputSpace& inputs() const { return inputs_; }
  // Whether std/CI carry information (a GP) or are identically zero (a deterministic law).
  virtual bool has_uncertainty() const = 0;

  // Validates each point (non-finite, negative pressure/velocity/temperature → INVALID_INPUT with
  // NaN outputs; outside the training box → EXTRAPOLATED, still answered) and evaluates the rest.
  Evaluation evaluate(const QueryBatch& x, const EvaluationRequest& what) const;

  // Writes the kind-specific groups; the common header is written by save_model().
  virtual void write(h5::Writer& out) const = 0;

  // Free text: provenance, accuracy figures (shown by describe/train).
  virtual std::string summary() const = 0;

 protected:
  explicit FrictionModel(InputSpace inputs) : inputs_(std::move(inputs)) {}
  // Evaluates valid points only (x has no invalid rows); fills mu and whatever `what` asks for.
  // std is filled when what.std or what.ci_level > 0.
  virtual void evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const = 0;

 private:
  InputSpace inputs_;
};

// Two-sided normal quantile z such that P(|Z| ≤ z) = level (Boost.Math).
double normal_quantile_two_sided(double level);

}  // namespace mufric
