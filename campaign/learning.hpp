#pragma once
// On-line learning (`mufric learn`, issue 62): the service learns where meso codes ask. A learner is
// a process of its own beside `serve` (the server stays a stateless reader of model files); one
// directory holds its state. Each round:
//   1. reads the rows the server logged since the last round (`serve --log-uncertain`: queries whose
//      95 % interval is wide, and queries outside the box) and rests while they are a small share of
//      the model's queries;
//   2. grows the campaign's box toward them and plans a batch by the active-learning rules of
//      `dataset refine` (campaign/refine.hpp), within the round's samples and the core-hour budget;
//   3. runs them (the local work pool; the database is rewritten after every sample);
//   4. retrains the campaign's GP, with the served model's extrapolation policy, μ range and grids;
//      a served calibrated model (surrogate/calibration/calibrated_model.hpp) is recalibrated on its measurements
//      with the retrained GP as its emulator (the picks of step 2 then sit at the queried conditions
//      and at the coefficients' posterior samples);
//   5. gates it (gate_candidate): the new version replaces the served file only if it is no worse on
//      what the served version knew, covers its new draws and keeps its grid certified; else it is
//      kept aside with the reason; a round refused for its values (not for its grid) has its samples
//      quarantined: marked failed in the database with the reason, μ kept, so that later rounds train
//      without them. Publishing is a rename in the served folder, which the server's
//      reload picks up; every published version is kept for rollback (learn_rollback).
// Every step writes its files atomically and records itself in DIR/learn.json before the next, so
// kill -9 at any moment loses no finished run and the next `learn` resumes at the step it stopped.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "campaign/dataset_generation.hpp"
#include "common/files.hpp"  // file_version, the versions a learner keeps
#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/calibration/calibration_workflow.hpp"  // kDefaultCalibrationMaxSteps
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// What the learner works on, fixed when its directory is made (learn_init) and kept in DIR/learn.json.
struct LearnSetup {
  std::string db;            // the campaign database (plan-based; extended in place)
  std::string served_model;  // the served file (FOLDER/NAME.h5), replaced by each published version
  std::string log;           // the server's uncertain log of that model (LOGDIR/NAME.csv; NAME.outside.json beside)
  long long round_samples = 8;      // runs a round plans, at most
  double budget_core_hours = 1.0;   // all rounds together
  // The loop rests while the rows logged since the last round are fewer than this share of the
  // model's queries in that time (from NAME.outside.json; without it, while no row was logged).
  double rest_below = 0.01;
  double grow_coverage = 1.0;       // grow_box's quantile of the logged rows outside the box
  unsigned long long seed = 1;      // candidate sets and GP restarts
  int restarts = 2;                 // GP restarts per fit
};

// The gate's verdict on a candidate against the served version (gate_candidate).
struct GateDecision {
  bool publish = false;
  std::string reason;               // a sentence: why published, or why kept aside
  long long old_points = 0;         // the served version's training points, found in the candidate's
  double served_loo_rmse = 0.0;     // leave-one-out RMSE at those points: the served version's ...
  double candidate_loo_rmse = 0.0;  // ... and the candidate's (μ units)
  double allowed_loo_rmse = 0.0;    // the most the candidate may reach
  long long new_points = 0;         // the candidate's points the served version had not
  long long new_covered = 0;        // of them inside their leave-one-out 95 % interval
  bool grid_certified = true;       // the candidate's grid meets the tolerances the served one met
  // A calibrated model's: its measurements, and of them inside the candidate's 95 % posterior
  // predictive interval widened by the measurement's own SD.
  long long measurements = 0;
  long long measurements_covered = 0;
  // Kept aside for the round's values (worse on the served version's points, its new points or the
  // measurements not covered), not for its grid or its database: the round's samples are quarantined.
  bool values_refused = false;
};

// Leave-one-out is the held-out error of each version on the served version's own points (R&W eq.
// 5.12): the candidate must reach at most the served one's RMSE plus kGateRmseSlack standard errors of
// an RMS of n terms (RMSE/√(2n), the χ distribution's); its new points must be covered at a rate a
// one-sided binomial test at kGateCoverageSignificance does not reject against 95 %; a served grid
// that met `tolerances` must be met again.
inline constexpr double kGateRmseSlack = 2.0;
inline constexpr double kGateCoverageSignificance = 0.01;
GateDecision gate_candidate(const GaussianProcess& served, const GaussianProcess& candidate,
                            const FastEvaluatorOptions& tolerances);
// A recalibrated model: its emulator gated as a GP is (its grid aside), its measurements covered at a
// rate the same binomial test does not reject, and its own grid certified where the served one was.
GateDecision gate_calibrated_candidate(const CalibratedModel& served, const CalibratedModel& candidate,
                                       const FastEvaluatorOptions& tolerances);
// P(X ≤ k) for X ~ Binomial(n, p), the gate's coverage test.
double binomial_lower_tail(long long k, long long n, double p);

// One round's record in DIR/learn.json.
struct LearnRound {
  int number = 0;
  std::string step;  // "run", "train", "gate", "done"
  long long first_plan_row = 0, end_plan_row = 0;  // the plan rows it planned
  long long logged_rows = 0;  // rows of the log it answered
  double uncertain_share = -1.0;  // logged rows / queries since the last round (−1: not known)
  double run_core_seconds = 0.0;  // micro-model time it spent
  std::string candidate;          // the retrained model's file (DIR/candidates/round-K.h5)
  GateDecision gate;
  long long quarantined = 0;      // its samples marked failed because the gate refused their values
  std::string version;            // the candidate's version (its SHA-256, 16 hex digits, as the server names it)
  std::string finished_utc;
};

struct LearnState {
  LearnSetup setup;
  long long log_offset = 0;       // bytes of the log consumed (whole lines)
  long long log_file_id = 0;      // the log file the offset is in (its inode; 0: not yet read)
  long long queries_seen = -1;    // the model's query count at the last look (NAME.outside.json; −1: none)
  double spent_core_seconds = 0.0;
  std::vector<LearnRound> rounds;
  // Every version the served folder had from the learner, oldest first: the one it found, then each
  // published or rolled back to; each kept as DIR/versions/<version>.h5.
  struct Served {
    std::string version, utc, how;  // how: "found", "published by round K", "rolled back"
  };
  std::vector<Served> served;
};

// Makes DIR with its state; throws Error naming what is missing or wrong (the database without plan
// rows, the served file not a GP, a directory that already holds a learner).
void learn_init(const std::string& directory, const LearnSetup& setup);
LearnState read_learn_state(const std::string& directory);

// A round's runs handed to an engine other than the local work pool (the mufric executable's Slurm
// array, deploy/slurm): it must leave every plan row in [first, end) answered in the database at
// db_path (converged or failed), resuming what an earlier call for the same round began (work_dir is
// the round's own, kept across calls).
struct RoundRuns {
  std::string db_path, work_dir;
  long long first_plan_row = 0, end_plan_row = 0;
};

struct LearnRunOptions {
  std::function<void(const RoundRuns&)> run_rows;  // empty: the local work pool
  int jobs = 1;              // samples run at once
  int threads_per_job = 1;   // for the core-hour count
  int rounds = 1;            // rounds this call may finish (each ends published, kept aside, or resting)
  // The evaluator of a sample, made from the database as it is when a round runs (the mufric
  // executable: the micro-model with the database's scene). Required.
  std::function<SampleEvaluator(const Dataset& db)> make_evaluator;
  FastEvaluatorOptions fast;  // the candidate's grids; max_work 0: the GP's default budget
  int recalibration_max_steps = kDefaultCalibrationMaxSteps;  // a calibrated model's sampler, at most
  std::function<void(const std::string& line)> progress;  // one line per step and per sample; may be empty
};

// Why learn_rounds returned.
enum class LearnStop { rounds_done, resting, budget_spent };
struct LearnReport {
  int rounds_finished = 0;
  LearnStop stop = LearnStop::rounds_done;
};
// Resumes an unfinished round, then runs new ones. Holds DIR's lock (an Error if another learner has it).
LearnReport learn_rounds(const std::string& directory, const LearnRunOptions& options);

// Puts a version the learner kept (any of LearnState::served) back as the served file, atomically.
void learn_rollback(const std::string& directory, const std::string& version);


}  // namespace mufric
