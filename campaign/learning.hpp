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
// The parts: the state and its lock (campaign/learning_state.hpp), the intake of the log
// (campaign/learning_log.hpp), the gate's statistics (campaign/learning_gate.hpp); the rounds here.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "campaign/dataset_generation.hpp"
#include "campaign/learning_gate.hpp"
#include "campaign/learning_state.hpp"
#include "common/files.hpp"  // file_version, the versions a learner keeps
#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/calibration/calibration_workflow.hpp"  // kDefaultCalibrationMaxSteps
#include "surrogate/gp/gp_grids.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {




// Makes DIR with its state; throws Error naming what is missing or wrong (the database without plan
// rows, the served file not a GP, a directory that already holds a learner).
void learn_init(const std::string& directory, const LearnSetup& setup);

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
