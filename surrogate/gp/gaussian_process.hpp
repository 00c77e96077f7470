#pragma once
// Gaussian-process regression (Rasmussen & Williams 2006, Algorithm 2.1) with the scikit-learn
// kernel convention k(x, x') = σ² exp(−½ Σᵢ ((xᵢ − x'ᵢ)/lᵢ)²) + σn² δ(x, x'), inputs scaled to the
// unit box of the declared training box, outputs normalised by mean and (population) std.
#include <memory>
#include <string>

#include <Eigen/Dense>

#include "surrogate/core/friction_model.hpp"

namespace mufric {

class FastEvaluator;

struct GpHyperParameters {
  double signal_variance = 1.0;      // σ², in normalised-output units
  Eigen::VectorXd length_scales;     // lᵢ, in unit-box coordinates
  double noise_variance = 0.0;       // σn², 0 when the model has no white-noise term
  bool noise_term = true;

  // θ = [log σ², log l₁…l_d, (log σn²)] — the optimiser's coordinates.
  Eigen::VectorXd to_log() const;
  static GpHyperParameters from_log(const Eigen::VectorXd& theta, Eigen::Index dims, bool noise_term);
  Eigen::Index count() const { return length_scales.size() + (noise_term ? 2 : 1); }
};

// Threads one evaluation may use: OpenMP's current limit, or 1 when called from inside an active
// parallel region (a meso code's OpenMP loop calling at once from several threads), so that no team of our
// own is started inside the caller's and the cores are not oversubscribed; at most max_threads if > 0.
int evaluation_team_size(int max_threads = 0);

// What a GP's standard deviation stands for.
//   new_run           a new micro-model run's μ (model variance + learned noise): data without their own errors
//   shared_scatter    the mean over all draws, plus the samples' common scatter added as one constant
//                     (data whose samples share their draws: the common error cannot average out)
//   mean_over_draws   the mean over all draws of the roughness statistics (stochastic kriging of
//                     independent draws: the model variance alone, which shrinks with the campaign)
enum class IntervalMeaning { new_run, shared_scatter, mean_over_draws };
std::string_view to_string(IntervalMeaning m);  // "new-run", "shared-scatter", "mean-over-draws"
// For DescribeModel and `describe`.
std::string gp_interval_meaning(IntervalMeaning m);

struct GpTrainingSummary;
// The leave-one-out figures in words, saying what each is; noisy_samples: a model whose samples carry
// their own noise (stochastic kriging), where the errors are mostly that noise.
std::string leave_one_out_text(const GpTrainingSummary& summary, bool noisy_samples);

// Figures from training, stored in the model file and shown by `describe`.
struct GpTrainingSummary {
  double log_marginal_likelihood = 0.0;
  double loo_mean_relative_error = 0.0;  // leave-one-out, closed form (R&W eq. 5.12)
  double loo_max_relative_error = 0.0;
  double loo_rmse = 0.0;                 // in μ units
  double loo_coverage_95 = 0.0;          // fraction of samples inside their LOO 95 % interval
  // RMS of the LOO residuals over their predictive std (each sample's own noise included): 1 when the
  // interval is as wide as the errors are. Negative: not known (a file from before it was kept,
  // too large to recompute at load: `mufric upgrade --rebuild` stores it).
  double loo_standardised_rms = -1.0;
  long long starts = 0;
  long long best_start = 0;
  double seconds = 0.0;
  std::string dataset_path;
  std::string dataset_sha256;
  std::string dataset_description;  // the campaign behind the data (TrainingSet::description); "" before it was kept
  std::string code_version;
  std::string created_utc;
};

// patch_std = exp(½ m) of the scatter GP's log variance m: an absolute error δ in m is a relative
// error δ/2 in patch_std (to first order), so a fast evaluator of m within 2R holds patch_std to R.
inline constexpr double patch_scatter_log_variance_tolerance(double std_relative_tolerance) {
  return 2.0 * std_relative_tolerance;
}

class GaussianProcess final : public FrictionModel {
 public:
  struct State {
    InputSpace inputs;
    Eigen::MatrixXd x_train;  // n × d, SI
    Eigen::VectorXd y_train;  // n, μ
    double y_mean = 0.0;
    double y_scale = 1.0;
    GpHyperParameters hyper;
    double jitter = 0.0;       // added to the diagonal beyond σn² when factorising
    // Known noise of each training point (normalised-output variance, (μ_std / y_scale)², R&W eq.
    // 2.20 with a diagonal of per-point variances, as scikit-learn's `alpha` array); empty: none.
    Eigen::VectorXd known_noise;
    // The micro-model's own scatter of μ (its standard error over tool phases and realisations), the
    // root mean square over the training points, μ units; 0 when the data carry none. It is part of
    // the served interval: the spread of the μ a converged micro-model would give about the mean
    // over all tools of the same roughness statistics.
    double micro_std_error = 0.0;
    // mean_over_draws: the served variance is the latent mean's alone (Ankenman, Nelson & Staum 2010,
    // eq. 7's MSE), without the learned noise or micro_std_error: both belong to a sample, not to
    // the mean. Otherwise new_run or shared_scatter, by micro_std_error.
    bool interval_of_mean = false;
    // Ordinary kriging: y_mean is the constant mean estimated by generalised least squares from the
    // data, β̂ = 1ᵀK⁻¹y / 1ᵀK⁻¹1, and every served variance adds that estimate's own, (1 − 1ᵀK⁻¹k)² /
    // 1ᵀK⁻¹1 (Ankenman, Nelson & Staum 2010, eqs. 7–8; the BLUP's MSE of Sacks, Welch, Mitchell &
    // Wynn 1989, Stat. Sci. 4(4):409, with a constant regressor). false: y_mean is the samples' plain average, taken as known (simple kriging,
    // scikit-learn's normalize_y), which a few samples whose signal variance sits at its lower bound
    // make far too narrow (bench/studies/served_interval/README.md, "calibration").
    bool mean_estimated = false;
    Eigen::VectorXd alpha;     // K⁻¹ (y − mean)/scale
    Eigen::MatrixXd cholesky;  // lower factor of K, n × n
    GpTrainingSummary summary;
  };

  // Takes a complete state (after training or loading) and precomputes the prediction caches.
  explicit GaussianProcess(State state);

  std::string_view kind() const override { return "gp"; }
  bool has_uncertainty() const override { return true; }
  bool has_patch_scatter() const override { return patch_scatter_ != nullptr; }
  void write(h5::Writer& out) const override;
  std::string summary() const override;
  KindDescription kind_description() const override;
  const State& state() const { return state_; }

  // Rebuilds a model from the file's groups; refuses inconsistent contents (names the field).
  static GaussianProcess read(const h5::Reader& in, InputSpace inputs);

  // The certified fast evaluator (surrogate/fast/fast_evaluator.hpp) answers, instead of the exact
  // model, the points inside the box when its bound is within the request's tolerances; μ is then
  // the same whatever else is asked (the gradient, always exact, does not move μ). Stored in the model file.
  void attach_fast_evaluator(std::shared_ptr<const FastEvaluator> fast);
  const FastEvaluator* fast_evaluator() const { return fast_.get(); }

  IntervalMeaning interval_meaning() const;

  // The patch scatter (issue 33): a GP of the log per-draw variance of μ over the same inputs
  // (surrogate/gp/stochastic_kriging.hpp), served as its own output, never mixed into the interval.
  // (The scatter's output range is made unbounded: a log variance, not a μ.)
  void attach_patch_scatter(std::shared_ptr<const GaussianProcess> scatter);
  // For a GP whose output is not a μ: FrictionModel::evaluate (and so a fast evaluator's build and
  // its load-time check) no longer clamps it to μ's range.
  void set_unbounded_output();
  const GaussianProcess* patch_scatter() const { return patch_scatter_.get(); }
  // The scatter GP's own fast evaluator (of its log variance, built to
  // patch_scatter_log_variance_tolerance); the scatter must be attached first.
  void attach_patch_scatter_fast_evaluator(std::shared_ptr<const FastEvaluator> fast);
  // The per-draw standard deviation of μ at SI points (rows), exp(½ m(x)) of the scatter GP's mean;
  // empty when the model has none. Outside the box, m at the nearest face (clamped). With a relative
  // tolerance R > 0 the scatter's fast evaluator answers when its bound holds patch_std to R; 0: exact.
  Eigen::VectorXd patch_std(const QueryBatch& x, double std_relative_tolerance = 0.0) const;
  // exp(½ m(x)) of a GP `log_variance` of a log variance, each point clamped to its box (NaN for a
  // non-finite point): what patch_std serves, and what stochastic kriging puts on its diagonal.
  static Eigen::VectorXd std_from_log_variance(const GaussianProcess& log_variance, const QueryBatch& x,
                                               double std_relative_tolerance = 0.0);

  // The latent mean's posterior at SI points (rows; unclamped, anywhere): its mean and the covariance
  // between two sets of points, μ units (R&W eqs. 2.23–2.24 with k(a, b) for k(x*, x*), plus an
  // estimated mean's covariance (1 − 1ᵀK⁻¹k_a)(1 − 1ᵀK⁻¹k_b) / 1ᵀK⁻¹1 under State::mean_estimated;
  // Sacks et al. 1989), without the learned noise or micro_std_error: the interval of the mean,
  // jointly. A calibration's likelihood needs it whole: the emulator's errors at nearby
  // measurements are correlated, and a diagonal would count them as independent evidence.
  Eigen::VectorXd latent_mean(const Eigen::MatrixXd& x) const;
  Eigen::MatrixXd latent_covariance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) const;
  Eigen::MatrixXd latent_covariance(const Eigen::MatrixXd& x) const;  // of x with itself
  Eigen::VectorXd latent_variance(const Eigen::MatrixXd& x) const;    // its diagonal alone
  // The same from a set of points' correlations with the training set, formed once (n²/2
  // multiply-adds a point): a calibration's posterior keeps its measurements' for every prediction.
  struct LatentPoints {
    Eigen::MatrixXd scaled;    // rows × d, in the training inputs' scaled space
    Eigen::VectorXd mean;      // the latent mean, μ units (latent_mean's bits)
    Eigen::MatrixXd whitened;  // L⁻¹ k̂, n × rows
    // Rows [first, first + count) alone: the same bits as formed with the others.
    LatentPoints rows(Eigen::Index first, Eigen::Index count) const {
      return {scaled.middleRows(first, count), mean.segment(first, count), whitened.middleCols(first, count)};
    }
  };
  // Up to kLatentSmallBatch points are whitened by Eigen's product; more in blocks of kEvaluationBlockRows
  // through the batch variance's product (OpenBLAS's dtrmm in a portable build, each block full and
  // zero-padded). A caller that wants a point's bits independent of the batch keeps its row count
  // on one side of the line (a calibration's likelihood: its measurements; its predictive: whole blocks).
  LatentPoints latent_points(const Eigen::MatrixXd& x) const;
  // Below this a padded block costs more than the faster product saves (128/16 = 8 against 2.6×).
  static constexpr Eigen::Index kLatentSmallBatch = 16;
  Eigen::MatrixXd latent_covariance(const LatentPoints& a, const LatentPoints& b) const;
  Eigen::VectorXd latent_variance(const LatentPoints& x) const;

  // The model file's groups under `group` ("/gp"; the patch scatter's under "/gp/patch_scatter").
  // Whether a model stored inside another's file (a calibrated model's campaign GP) keeps its grid.
  enum class GridInFile { with, without };
  void write_group(h5::Writer& out, const std::string& group, GridInFile grid = GridInFile::with) const;
  static GaussianProcess read_group(const h5::Reader& in, InputSpace inputs, const std::string& group);

  // Store the n × n factor in model files up to this size; larger models refactorise on load.
  static constexpr Eigen::Index kStoreCholeskyUpTo = 2000;


 protected:
  void evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const override;
  Eigen::VectorXd patch_std_valid(const QueryBatch& x, const EvaluationRequest& what) const override;

 private:
  void evaluate_exact(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const;
  void evaluate_block(const QueryBatch& x, Eigen::Index first, Eigen::Index count, const EvaluationRequest& what,
                      Eigen::MatrixXd& k_block, Eigen::MatrixXd& v_block, Evaluation& out, long long& clamped) const;

  // v_block's first columns ← L⁻¹ k_block (k_block: n × at most kEvaluationBlockRows columns): Eigen's
  // product in a build for a vector ISA, OpenBLAS's dtrmm on a full zero-padded block in a portable one.
  void whiten_block(const Eigen::Ref<const Eigen::MatrixXd>& k_block, Eigen::MatrixXd& v_block) const;
  // ((x − lo)/width)/l per row: the space the training inputs are scaled to.
  Eigen::MatrixXd scaled_queries(const Eigen::MatrixXd& x) const;
  void require_query_columns(const Eigen::MatrixXd& x) const;
  // 1 − σ² uᵀV per column of a whitened V (an estimated mean's share); empty without one.
  Eigen::RowVectorXd unexplained_trend(const Eigen::MatrixXd& whitened) const;
  // exp(−½ |s_i − q|²) for every scaled training input s_i and a scaled query q.
  void correlations_with_training(const Eigen::RowVectorXd& scaled_query, Eigen::Ref<Eigen::ArrayXd> correlation) const;
  // μ = ȳ + Σ_i w_i k_i in one fixed summation order, whatever the request, batch or alignment: asking
  // for the interval or the gradient must not change μ by a single bit (an explicit meso run and its
  // twin would part ways). Not inlined, so that every caller runs the same instructions.
  [[gnu::noinline]] double mean_from_correlations(const double* correlation) const;
  // μ of each scaled row (mean_from_correlations) and, unless null, its correlations as column b.
  void means_and_correlations(const Eigen::MatrixXd& scaled, Eigen::Ref<Eigen::VectorXd> mean,
                              Eigen::MatrixXd* correlations) const;
  // For each column k_b of a few kernel vectors, reading each row of L⁻¹ once: |L⁻¹ k_b|² (row 0)
  // and, with an estimated mean, uᵀ L⁻¹ k_b = 1ᵀK⁻¹k_b (row 1; 0 otherwise).
  Eigen::Matrix<double, 2, Eigen::Dynamic> norms_row_by_row(const Eigen::MatrixXd& kernels, int max_threads) const;
  // The normalised variance of a query from σ², |L⁻¹k̂|² and uᵀL⁻¹k̂ (k̂: its correlations).
  double normalised_variance(double squared_norm, double trend_dot) const;

  State state_;
  // L⁻¹, row-major. The same n²/2 multiply-adds per query as a triangular solve with L, but without
  // its chain of dependent steps: a block of queries is a triangular matrix product, and one query
  // is a streaming matrix–vector product whose rows two cores split between their own L2 caches.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> inverse_factor_;
  Eigen::Index row_split_ = 0;  // rows [0, split) and [split, n) hold equal halves of the entries
  // An estimated mean's variance: u = L⁻¹1 and 1ᵀK⁻¹1 = uᵀu (normalised units), once per model, so
  // that a query's 1ᵀK⁻¹k is one more dot product with the L⁻¹k its variance forms anyway.
  Eigen::VectorXd trend_direction_;
  double trend_precision_ = 0.0;
  std::shared_ptr<const FastEvaluator> fast_;
  std::shared_ptr<const GaussianProcess> patch_scatter_;
  Eigen::RowVectorXd box_lo_;
  Eigen::RowVectorXd inverse_box_width_;
  Eigen::MatrixXd scaled_train_;       // x_unit / l, n × d
  Eigen::VectorXd weights_;            // y_scale σ² α: mean = y_mean + Σ weights_i exp(−½ r²)
  Eigen::MatrixXd weights_by_input_;   // weights_ ∘ scaled_train_, for dμ/dx
};

// Unit-box coordinates of SI inputs: (x − lo) / (hi − lo) per input.
Eigen::MatrixXd to_unit_box(const Eigen::MatrixXd& x, const InputSpace& inputs);

// Overwrites scaled squared distances r² with exp(−½ r²), floored at 1e-150 (never subnormal).
void rbf_correlation_in_place(Eigen::Ref<Eigen::ArrayXd> values);

// exp(−½ |a_i − b_j|²) between the rows of two sets of points already divided by their length
// scales (rows(a) × rows(b)), vectorised as rbf_correlation_in_place.
Eigen::MatrixXd rbf_correlations(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// Lower triangle (and diagonal) of the signal covariance σ² exp(−½ r²) for unit-box inputs.
void rbf_signal_covariance(const Eigen::MatrixXd& x_unit, const GpHyperParameters& hyper, Eigen::MatrixXd& kf);

}  // namespace mufric
