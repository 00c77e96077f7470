// `mufric learn init / run / status / rollback`: the on-line learner (campaign/learning.hpp). Here
// flags are parsed, the sample evaluator wired in and progress printed.
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "app/commands.hpp"
#include "app/sample_evaluators.hpp"
#include "campaign/learning.hpp"
#include "campaign/slurm_rounds.hpp"
#include "common/error.hpp"
#include "common/files.hpp"

namespace mufric::app {
namespace {

struct LearnRunCommand {
  std::string directory, simulator, slurm_submit = MUFRIC_SLURM_SUBMIT, sbatch_args;
  int slurm_tasks = 0;
  double slurm_poll_seconds = 5.0;
  int rounds = 1, jobs = 1, threads = 0;
  double follow_seconds = 0.0, sample_timeout = 0.0;
  double fast_max_gigawork = 0.0;
};

void print_line(const std::string& line) {
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

void run_learner(const LearnRunCommand& c) {
  LearnRunOptions o;
  o.jobs = c.jobs;
  o.threads_per_job = threads_per_job(c.jobs, c.threads);
  o.rounds = c.rounds;
  o.fast.max_work = c.fast_max_gigawork * 1e9;
  o.progress = print_line;
  const std::string simulator = c.simulator;
  const int threads = o.threads_per_job;
  const double timeout = c.sample_timeout;
  o.make_evaluator = [simulator, threads, timeout](const Dataset& db) {
    return database_evaluator(db, "the learner's database", simulator, threads, timeout);
  };
  if (c.slurm_tasks > 0) {
    o.threads_per_job = 1;  // dataset-array.sbatch asks one CPU per task
    const std::string mufric = std::filesystem::read_symlink("/proc/self/exe").string();
    const SlurmRoundOptions slurm{.mufric = mufric, .simulator = c.simulator, .submit_script = c.slurm_submit,
                                  .sbatch_args = c.sbatch_args, .tasks = c.slurm_tasks, .poll_seconds = c.slurm_poll_seconds,
                                  .progress = print_line};
    o.run_rows = [slurm](const RoundRuns& r) { run_round_on_slurm(r, slurm); };
  }
  for (;;) {
    const LearnReport r = learn_rounds(c.directory, o);
    if (r.stop == LearnStop::budget_spent || c.follow_seconds <= 0.0) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(c.follow_seconds));
  }
}

}  // namespace

void add_learn_command(CLI::App& app) {
  auto* learn = app.add_subcommand(
      "learn", "On-line learning: the server's uncertain queries -> micro-model runs -> retrain -> gated publish");
  learn->require_subcommand(1);
  learn->footer(
      "A learner runs beside `mufric serve --log-uncertain LOGDIR`, in a directory of its own. Each round reads the\n"
      "queries the server logged since the last one, grows the campaign's box toward them, plans a batch where the\n"
      "model is least certain (the rules of `dataset refine`), runs it, retrains, and publishes the new version into\n"
      "the served folder only if it passes the gate: no worse on the points the served version knew (leave-one-out),\n"
      "its new points inside their 95 % intervals, its fast evaluator certified as the served one was. Otherwise the\n"
      "version is kept aside with the reason. A served calibrated model (mufric calibrate --model-out) is recalibrated\n"
      "on its measurements with the retrained GP as its emulator, then gated on its emulator as above and on its\n"
      "measurements (inside its 95 % predictive interval no less often than a 95 % interval may, or than the served\n"
      "version). Every step is recorded before the next: kill the learner at any moment and `learn run` resumes it.");

  auto setup = std::make_shared<LearnSetup>();
  auto dir = std::make_shared<std::string>();
  auto* init = learn->add_subcommand("init", "Make a learner's directory for one served model and its campaign");
  init->add_option("directory", *dir, "The learner's directory (made; its state is DIR/learn.json)")->required();
  init->add_option("--db", setup->db, "The campaign database (dataset plan + run), extended in place")->required()->check(CLI::ExistingFile);
  init->add_option("--model", setup->served_model,
                   "The served model file (FOLDER/NAME.h5), replaced by published versions: the campaign's GP, or a model\n"
                   "calibrated through it")
      ->required()->check(CLI::ExistingFile);
  init->add_option("--log", setup->log, "The server's log of that model (LOGDIR/NAME.csv of serve --log-uncertain LOGDIR)")->required();
  init->add_option("--round-samples", setup->round_samples, "Runs a round plans, at most")->capture_default_str()->check(CLI::Range(1LL, 100000LL));
  init->add_option("--budget-core-hours", setup->budget_core_hours, "Core-hours of runs for all rounds together")
      ->capture_default_str()->check(FiniteRange(1e-6, 1e9));
  init->add_option("--rest-below", setup->rest_below,
                   "Rest while the queries logged since the last round are below this share of the model's queries")
      ->capture_default_str()->check(FiniteRange(0.0, 0.999));
  init->add_option("--grow-coverage", setup->grow_coverage, "Quantile of the logged rows outside the box the box grows to cover")
      ->capture_default_str()->check(FiniteRange(0.01, 1.0));
  init->add_option("--seed", setup->seed, "Seed of the candidate sets and the fits")->capture_default_str();
  init->add_option("--restarts", setup->restarts, "GP optimiser restarts per fit")->capture_default_str()->check(CLI::Range(0, 64));
  init->callback([setup, dir] {
    learn_init(*dir, *setup);
    std::printf("learner %s: %s serving version %s, campaign %s, log %s\n", dir->c_str(), setup->served_model.c_str(),
                file_version(setup->served_model).c_str(), setup->db.c_str(), setup->log.c_str());
  });

  auto run = std::make_shared<LearnRunCommand>();
  auto* run_cmd = learn->add_subcommand("run", "Resume an unfinished round, then run new ones");
  run_cmd->add_option("directory", run->directory, "The learner's directory (learn init)")->required()->check(CLI::ExistingDirectory);
  run_cmd->add_option("--rounds", run->rounds, "Rounds to finish now")->capture_default_str()->check(CLI::Range(1, 1000000));
  run_cmd->add_option("--follow", run->follow_seconds,
                      "Keep going: after the rounds, or while resting, look again every this many seconds (until the budget is spent)")
      ->check(FiniteRange(0.1, 86400.0));
  run_cmd->add_option("--jobs", run->jobs, "Samples run at once")->capture_default_str()->check(CLI::Range(1, 1024));
  run_cmd->add_option("--threads", run->threads, "Threads per sample (default: cores / jobs)")->check(CLI::Range(1, 1024));
  run_cmd->add_option("--sample-timeout", run->sample_timeout, "Stop a sample after this many seconds, recorded as failed (0: no limit)")
      ->capture_default_str()->check(FiniteRange(0.0, 1e7));
  run_cmd->add_option("--simulator", run->simulator, "The model file a simulator's campaign was run with (dataset run --simulator)")
      ->check(CLI::ExistingFile);
  run_cmd->add_option("--fast-max-work", run->fast_max_gigawork,
                      "Work budget of each candidate's fast evaluator, 10^9 multiply-adds (default: train's)")
      ->check(FiniteRange(1e-3, 1e9));
  run_cmd->add_option("--slurm-tasks", run->slurm_tasks,
                      "Run each round as a Slurm array of this many tasks (deploy/slurm/submit-dataset.sh) instead of the local pool")
      ->check(CLI::Range(1, 100000));
  run_cmd->add_option("--slurm-submit", run->slurm_submit, "The submission script")->capture_default_str();
  run_cmd->add_option("--sbatch-args", run->sbatch_args, "Extra sbatch options, e.g. \"--partition=compute --time=2:00:00\"");
  run_cmd->add_option("--slurm-poll", run->slurm_poll_seconds, "Seconds between looks at the queue")
      ->capture_default_str()->check(FiniteRange(0.1, 3600.0));
  run_cmd->callback([run] {
    if (run->slurm_tasks > 0 && !std::filesystem::exists(run->slurm_submit)) {
      throw Error("--slurm-submit " + run->slurm_submit + ": not found (deploy/slurm/submit-dataset.sh of the source tree)");
    }
    run_learner(*run);
  });

  auto status_dir = std::make_shared<std::string>();
  auto* status = learn->add_subcommand("status", "The learner's rounds, spend, gate decisions and kept versions");
  status->add_option("directory", *status_dir, "The learner's directory")->required()->check(CLI::ExistingDirectory);
  status->callback([status_dir] { std::fputs(learn_status_text(*status_dir).c_str(), stdout); });

  auto rollback_dir = std::make_shared<std::string>(), version = std::make_shared<std::string>();
  auto* rollback = learn->add_subcommand("rollback", "Serve a version the learner kept again (atomically)");
  rollback->add_option("directory", *rollback_dir, "The learner's directory")->required()->check(CLI::ExistingDirectory);
  rollback->add_option("version", *version, "The version (16 hex digits, as learn status and every answer name it)")->required();
  rollback->callback([rollback_dir, version] {
    learn_rollback(*rollback_dir, *version);
    std::printf("serving version %s again\n", version->c_str());
  });
}

}  // namespace mufric::app
