#pragma once
// Filling a dataset from a sampling plan, one sample at a time, so that nothing is lost on a crash:
// after every finished sample the whole database is rewritten to a temporary file and renamed over
// the old one (h5::Writer::commit), so a killed run loses only the samples in flight, and a re-run
// skips every plan row already answered — converged or failed (failures keep their reason and are
// retried only on request). A shard i/N takes the plan rows r with r mod N = i; shards write
// separate files, combined afterwards by merge_datasets.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/dataset_file.hpp"
#include "common/sample_outcome.hpp"

namespace mufric {

struct Shard {
  long long index = 0, count = 1;
};
// "i/N" with 0 ≤ i < N; throws Error naming `field`.
Shard parse_shard(const std::string& text, const std::string& field = "--shard");

struct GenerationProgress {
  long long finished = 0;   // samples of this invocation finished so far
  long long to_run = 0;     // samples this invocation runs
  long long failed = 0;     // of `finished`
  long long plan_row = 0;   // the sample just finished
  const SampleOutcome* outcome = nullptr;
  double sample_seconds = 0.0;
  double elapsed_seconds = 0.0;
};

struct GenerationOptions {
  Shard shard;
  int jobs = 1;               // samples evaluated concurrently
  bool retry_failed = false;  // run failed plan rows again (their old record is replaced)
  long long limit = -1;       // run at most this many samples (−1: all)
  std::function<void(const GenerationProgress&)> on_sample;  // called under the database lock
};

struct GenerationReport {
  long long planned = 0;       // plan rows in this shard
  long long already_done = 0;  // found in the database and skipped
  long long ran = 0, converged = 0, failed = 0;
  double seconds = 0.0;
};

// The base seeds of plan row `row` of a plan with independent draws: reproducible from the plan's seed
// and the row alone (the same plan gives the same seeds on any machine, shard or order), distinct
// between rows. SplitMix64 (Steele, Lea & Flood, OOPSLA 2014) mixes them; each seed is kept below
// 2^30 so that seed + draw stays a valid scene seed (0 … 2^31 − 1) for a `micro run --set` that
// reproduces the sample.
DrawSeeds row_draw_seeds(long long plan_seed, long long row);

// Which of the plan's rows some sample answers, converged or not.
std::vector<bool> answered_plan_rows(const Dataset& db);

// A dataset with no samples carrying `plan`'s inputs, plan (design, seed, box history), source and
// scene, stamped with this code's version: a new plan file, a new database, a merge's start.
Dataset empty_dataset(const Dataset& plan);

// The database at `db_path` for `plan`: read and checked against the plan (inputs, box, plan rows
// and scene must match, else Error naming what differs), or a new, empty one carrying the plan.
Dataset open_database(const std::string& db_path, const Dataset& plan);

GenerationReport generate_dataset(const Dataset& plan, const std::string& db_path, const SampleEvaluator& evaluate,
                                  const GenerationOptions& options);

// Appends one sample (diagnostics missing on either side are NaN), with the seeds its draws used
// (none: the scene's own) and its draws' μ.
void append_sample(Dataset& d, const Eigen::VectorXd& x, long long plan_row, const SampleOutcome& outcome,
                   const std::optional<DrawSeeds>& seeds = std::nullopt);

struct MergeReport {
  long long files = 0, samples_read = 0, duplicates_removed = 0, converged = 0, failed = 0;
  long long plan_rows = 0, plan_rows_missing = 0;
};
// Combines shard databases of one plan. Different scenes or code versions are refused unless
// `allow_mixed`; samples answering the same plan row are kept once (a converged one over a failed
// one, else the first).
Dataset merge_datasets(const std::vector<std::string>& paths, bool allow_mixed, MergeReport& report);

}  // namespace mufric
