#pragma once
// A calibrated model (issue 51): μ(p, v, T) served as the posterior predictive of a calibration
// (surrogate/calibration/calibration.hpp) — the campaign's GP over the conditions and the interface law's
// coefficients θ, θ's posterior samples given measured friction, and the discrepancy δ — so that a
// meso code asks for μ at its conditions alone and gets the interval of everything not known: the
// roughness mean (the campaign's interval of the mean), θ's posterior and δ.
//
//   μ(x) = E_s[ m_s(x) ],   σ²(x) = E_s[ v_s(x) ] + Var_s[ m_s(x) ]
//
// with m_s, v_s the mean and variance of ζ(x) = η(x, θ_s) + δ(x) given the measurements at posterior
// sample s (Kennedy & O'Hagan 2001, eq. 6). Exact evaluation costs a few GP covariances per sample;
// a certified fast evaluator (surrogate/fast/fast_evaluator.hpp) over the served box answers instead
// where its bound meets the request, as a GP's does. The patch scatter is the campaign's at the
// posterior median of θ.
#include <memory>
#include <string>
#include <vector>

#include "surrogate/calibration/calibrated_posterior.hpp"
#include "surrogate/fast/fast_evaluator.hpp"
#include "surrogate/core/friction_model.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// What a calibration was made from, for `describe` and the file.
struct CalibrationRecord {
  std::string data_source;      // the measurement file as given, with its '#' provenance lines
  std::string priors;           // the priors in words
  std::vector<ParameterSummary> posterior;  // per coordinate, as `calibrate` printed it
  int walkers = 0, steps = 0, burn_in_steps = 0;
  unsigned long long seed = 0;
  double acceptance = 0.0;
  // The file keeps every prior the sampler used, so the calibration can be run again with another
  // emulator (false: a file written before it kept them).
  bool priors_kept = true;
};


class CalibratedModel final : public FrictionModel {
 public:
  // Served over the measurements' conditions, in their order, with the emulator's box; inputs held
  // for every measurement (a coefficient given by --fix) stay at their value. Throws Error naming
  // the input when a served one is not on the wire (a law coefficient).
  CalibratedModel(std::shared_ptr<const CalibratedPosterior> posterior, CalibrationRecord record);

  std::string_view kind() const override { return "calibrated"; }
  bool has_uncertainty() const override { return true; }
  bool has_patch_scatter() const override { return emulator_->has_patch_scatter(); }
  void write(h5::Writer& out) const override;
  std::string summary() const override;
  KindDescription kind_description() const override;

  static CalibratedModel read(const h5::Reader& in, InputSpace inputs);

  // The posterior predictive and its parts at served points (SI rows), exactly.
  CalibratedPrediction predict(const QueryBatch& x, int max_threads = 0) const;
  IntervalParts parts_at(const Eigen::RowVectorXd& x) const;
  // At the centre of the served box (what describe reports).
  const IntervalParts& centre_parts() const { return centre_parts_; }

  const GaussianProcess& emulator() const { return *emulator_; }
  const CalibrationProblem& problem() const { return posterior_->problem(); }
  const Eigen::MatrixXd& samples() const { return posterior_->samples(); }
  const CalibrationRecord& record() const { return record_; }

  // The certified grid over the served box (FastEvaluator), as a GP's.
  void attach_fast_evaluator(std::shared_ptr<const FastEvaluator> fast);
  const FastEvaluator* fast_evaluator() const { return fast_.get(); }
  // The grid's source: this model, its length scales (the emulator's along each served input, δ's
  // posterior median where shorter) and the multiply-adds of one exact evaluation.
  Eigen::VectorXd unit_length_scales() const;
  double exact_point_work() const;

 protected:
  void evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const override;
  Eigen::VectorXd patch_std_valid(const QueryBatch& x, const EvaluationRequest& what) const override;

 private:
  void evaluate_exact(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const;

  std::shared_ptr<const GaussianProcess> emulator_;
  std::shared_ptr<const CalibratedPosterior> posterior_;
  CalibrationRecord record_;
  IntervalParts centre_parts_;
  // Per coordinate (θ, then σ_δ and ℓ_δ with δ on), the median of the kept posterior samples: the
  // θ at which the patch scatter is read, and δ's length scale for the grid.
  Eigen::VectorXd sample_medians_;
  std::shared_ptr<const FastEvaluator> fast_;
};

}  // namespace mufric
