#pragma once
// Active learning on a plan-based database (`mufric dataset refine`): each round trains a GP on the
// converged samples, picks a batch of candidates by the largest posterior variance (each pick
// conditioning the next, away from failed points) — or, for a database of independent draws, trains
// by stochastic kriging and picks by the integrated variance of the mean each pick removes, among new
// points and more draws at the existing ones (replicates; surrogate/gp/active_learning.hpp) — appends them to the plan, runs them through
// generate_dataset and reads the database back, until the budget of runs is spent or nothing new
// could be run. Candidates are a Sobol' set in the plan box (shifted per round) plus the rows of a
// CSV (e.g. the server's --log-uncertain file) inside the box; with `grow` the box first grows toward
// that CSV's rows, and the change is recorded in the database's /plan/box_history. The database is
// rewritten after the growth, after every round's picks and after every sample.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "campaign/dataset_generation.hpp"
#include "common/dataset_file.hpp"
#include "common/sample_outcome.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/gp/gaussian_process.hpp"
#include "surrogate/gp/gp_training.hpp"

namespace mufric {

// The box growth (with `grow`), written before the first round.
struct BoxGrowth {
  bool grown = false;            // false: the box already covered the candidates
  long long candidate_rows = 0;  // rows of the candidates CSV
  std::string record;            // the /plan/box_history entry written (when grown)
};

// After each round's training.
struct RefineRound {
  int round = 0;                  // from 1
  long long training_samples = 0;
  double loo_mean_relative_error = 0.0, loo_max_relative_error = 0.0;
  const AccuracyReport* held_out = nullptr;  // on the test set (null without one), at the 95 % level
  std::string held_out_source;               // the test set's path
};

// Each candidate picked, in order.
struct RefinePick {
  std::size_t number = 0;  // from 1 within the round
  long long plan_row = 0;  // the plan row it became
  double std_at_pick = 0.0;
  // Independent draws: the mean posterior variance over the box the pick removes (μ units²), and
  // the plan row whose point it repeats with new draws (−1: a new point).
  double imse_reduction = 0.0;
  long long replicates_row = -1;
};

struct RefineOptions {
  std::string db;              // the database extended in place (made by dataset plan + run)
  std::string test;            // held-out database reported after every round ("": none)
  std::string candidates_csv;  // extra candidates with unit headers ("": none)
  std::string model_out;       // the GP trained after each round is written here ("": not written)
  bool grow = false;           // grow the box toward candidates_csv's rows first (needs candidates_csv)
  double grow_coverage = 1.0;  // quantile of the outside rows covered per input and side
  long long budget = 0;        // runs to spend
  int batch = 8, jobs = 1, restarts = 2;
  long long candidate_count = 4096;  // Sobol' candidates per round
  long long reference_count = 512;   // Sobol' points over which the integrated variance is averaged
  unsigned long long seed = 1;       // of the candidate sets and GP restarts
  // Leave the plan rows not yet run out of the plan before the first round, so that the budget goes
  // to the picks: a campaign that ran a prefix of its plan (e.g. the first 128 rows of a Sobol'
  // sequence) hands over to refinement. They must all follow the last row run (drop_pending_plan_rows).
  bool drop_pending = false;
  // The evaluator of the samples, made once after the box growth from the database as it then is
  // (the mufric executable: the micro-model with the database's scene). Required.
  std::function<SampleEvaluator(const Dataset& db)> make_evaluator;
  // Progress, in the order it happens; each may be empty.
  std::function<void(const BoxGrowth&)> on_box;
  std::function<void(long long dropped_rows)> on_drop;  // with drop_pending, after the database is rewritten
  std::function<void(const RefineRound&)> on_round;
  std::function<void(const RefinePick&)> on_pick;
  // Each sample run (under generate_dataset's lock), with its point in the database's inputs.
  std::function<void(const GenerationProgress&, const InputSpace& inputs, const Eigen::VectorXd& x)> on_sample;
};

struct RefineReport {
  long long spent = 0;  // runs made, of options.budget
};

// Removes the plan rows no sample answers from the database's plan and returns how many; the plan's
// design records the prefix ("sobol" becomes "sobol prefix of 128"). Throws Error, naming the rows,
// when a row not run lies before one that was (the rows' numbers, and with them the seeds of their
// draws, would change).
long long drop_pending_plan_rows(Dataset& db, const std::string& source);

// The steps of a round, for a caller that runs them itself (the learner, campaign/learning.hpp).
// The rows of a CSV with unit headers (the server's --log-uncertain file) in the box's input order, SI.
Eigen::MatrixXd logged_candidates(const std::string& path, const InputSpace& box);
// The plan's box grown toward the logged rows (sampling.hpp grow_box), the change recorded in the
// database's /plan/box_history naming `logged_source` and `grown_by`; samples already run stay valid
// (the old box is inside). Not written: the caller writes the database.
BoxGrowth grow_plan_box(Dataset& db, const Eigen::MatrixXd& logged, double coverage, const std::string& logged_source,
                        const std::string& grown_by);
// A campaign's GP: stochastic kriging for a database of independent draws, else a GP on the means.
GaussianProcess fit_campaign_gp(const TrainingSet& data, const GpTrainingOptions& options);
struct PickOptions {
  long long candidate_count = 4096;  // Sobol' candidates per round
  long long reference_count = 512;   // Sobol' points over which the integrated variance is averaged
  unsigned long long seed = 1;       // of the candidate sets
  // Average the variance a pick removes over the logged rows inside the box (where the meso code
  // asks) rather than over the box; the box while fewer than 32 rows are logged there.
  bool reference_from_logged = false;
};
// One round's picks (of at most `batch`) by `gp`, trained on `data` from `db`, among a Sobol' set of
// round `round` and the logged rows inside the box, appended to db's plan as rows (not run, not
// written); each pick's plan_row is its new row.
std::vector<RefinePick> append_refinement_picks(Dataset& db, const GaussianProcess& gp, const TrainingSet& data,
                                                const Eigen::MatrixXd& logged, const PickOptions& options, int round,
                                                int batch);

// Throws Error for a database without plan rows, and whatever reading, training, running or
// writing throws (the database then holds every sample finished so far).
RefineReport refine_dataset(const RefineOptions& options);

}  // namespace mufric
