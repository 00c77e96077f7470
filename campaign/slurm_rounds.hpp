#pragma once
// A learner round's runs as a Slurm array (`mufric learn run --slurm-tasks`), the engine beside the
// local work pool (campaign/learning.hpp LearnRunOptions::run_rows): the project's own scripts submit
// one shard per task and a merge job after all of them (deploy/slurm/submit-dataset.sh), and the queue
// is polled until the merged database is there.
#include <functional>
#include <string>

#include "campaign/learning.hpp"

namespace mufric {

struct SlurmRoundOptions {
  std::string mufric;          // the executable the tasks run
  std::string simulator;       // --simulator for the tasks ("" for the micro-model)
  std::string submit_script;   // deploy/slurm/submit-dataset.sh
  std::string sbatch_args;     // passed on to sbatch, as given
  int tasks = 0;               // array tasks (shards)
  double poll_seconds = 5.0;   // between looks at the queue
  std::function<void(const std::string&)> progress;  // one line per submission and silence; may be empty
};

// The round's runs as a Slurm array with the project's own scripts (deploy/slurm/submit-dataset.sh:
// one shard per task, then a merge job after all of them). Each shard starts as a copy of the
// campaign database, so that only the round's rows are pending in it; the merge keeps each plan row
// once. The job ids are kept in the round's directory: a learner killed while the jobs run waits for
// them again instead of submitting twice; jobs that ended without a merged database are submitted
// again, and their shards resume from the rows they finished.
void run_round_on_slurm(const RoundRuns& r, const SlurmRoundOptions& options);

}  // namespace mufric
