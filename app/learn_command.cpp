// `mufric learn init / run / status / rollback`: the on-line learner (campaign/learning.hpp). Here
// flags are parsed, the sample evaluator wired in and progress printed.
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <utility>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "app/commands.hpp"
#include "app/sample_evaluators.hpp"
#include "campaign/learning.hpp"
#include "common/error.hpp"
#include "common/files.hpp"

namespace mufric::app {
namespace {

// How long squeue may fail to answer (controller down or restarting) before the learner stops waiting.
constexpr double kSlurmSilenceLimitSeconds = 1800.0;

struct LearnRunCommand {
  std::string directory, simulator, slurm_submit = MUFRIC_SLURM_SUBMIT, sbatch_args;
  int slurm_tasks = 0;
  double slurm_poll_seconds = 5.0;
  int rounds = 1, jobs = 1, threads = 0;
  double follow_seconds = 0.0, sample_timeout = 0.0;
  double fast_max_gigawork = 0.0;
};

// The output of a shell command, and its exit status.
std::pair<std::string, int> shell(const std::string& command) {
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw Error("cannot run: " + command);
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = ::pclose(pipe);
  return {output, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

std::string quoted(const std::string& word) {
  std::string q = "'";
  for (const char c : word) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The round's runs as a Slurm array with the project's own scripts (deploy/slurm/submit-dataset.sh:
// one shard per task, then a merge job after all of them). Each shard starts as a copy of the
// campaign database, so that only the round's rows are pending in it; the merge keeps each plan row
// once. The job ids are kept in the round's directory: a learner killed while the jobs run waits for
// them again instead of submitting twice; jobs that ended without a merged database are submitted
// again, and their shards resume from the rows they finished.
void run_rows_on_slurm(const RoundRuns& r, const LearnRunCommand& c, const std::string& mufric) {
  namespace fs = std::filesystem;
  const std::string jobs_file = r.work_dir + "/jobs", merged = r.work_dir + "/db.h5";
  // Why the job waits ("None" while it runs), or "" once it has left the queue (squeue names a job
  // the controller has forgotten an invalid id). A controller that does not answer (down, restarting,
  // timing out) says nothing about the job: polled again until it has been silent for
  // kSlurmSilenceLimitSeconds, so that a restart of slurmctld does not make the learner resubmit a
  // round that is still running.
  auto silent_since = std::chrono::steady_clock::time_point{};
  const auto queue_reason = [&silent_since, &c](const std::string& job) {
    for (;;) {
      const auto [out, status] = shell("squeue -h -j " + job + " -o %r 2>&1");
      if (status == 0) {
        silent_since = {};
        return out;
      }
      if (out.find("Invalid job id") != std::string::npos) return std::string();
      const auto now = std::chrono::steady_clock::now();
      if (silent_since == std::chrono::steady_clock::time_point{}) {
        silent_since = now;
        std::printf("squeue does not answer about job %s (%s); asking again every %g s\n", job.c_str(),
                    out.substr(0, out.find('\n')).c_str(), c.slurm_poll_seconds);
        std::fflush(stdout);
      }
      if (std::chrono::duration<double>(now - silent_since).count() > kSlurmSilenceLimitSeconds) {
        throw Error("squeue has not answered about job " + job + " for " + std::to_string(static_cast<int>(kSlurmSilenceLimitSeconds)) +
                    " s (" + out.substr(0, out.find('\n')) + "); the job may still run: `mufric learn run` again waits for it");
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(c.slurm_poll_seconds));
    }
  };
  for (int attempt = 0; attempt < 2; ++attempt) {
    std::string merge_job;
    if (const auto text = read_whole_file(jobs_file)) merge_job = *text;
    if (merge_job.empty() || (queue_reason(merge_job).empty() && !fs::exists(merged))) {
      fs::remove(merged);
      for (int i = 0; i < c.slurm_tasks; ++i) {
        const std::string shard = r.work_dir + "/shard-" + std::to_string(i) + ".h5";
        if (!fs::exists(shard)) copy_file_atomically(r.db_path, shard);
      }
      // dataset-array.sbatch splits MUFRIC_RUN_ARGS on spaces (no quotes): a path with a space cannot pass.
      const std::string simulator = c.simulator.empty() ? "" : fs::absolute(c.simulator).string();
      if (simulator.find_first_of(" \t'\"") != std::string::npos) throw Error("--simulator " + simulator + ": a path with spaces or quotes cannot pass to the Slurm tasks");
      const std::string run_args = simulator.empty() ? "" : "--simulator " + simulator;
      const auto [out, status] = shell("MUFRIC=" + quoted(mufric) + " MUFRIC_RUN_ARGS=" + quoted(run_args) + " bash " +
                                       quoted(c.slurm_submit) + " " + quoted(r.db_path) + " " + quoted(r.work_dir) + " " +
                                       std::to_string(c.slurm_tasks) + " " + c.sbatch_args + " 2>&1");
      const auto at = out.find("merge job ");
      if (status != 0 || at == std::string::npos) throw Error("Slurm submission failed: " + out);
      merge_job = out.substr(at + 10, out.find_first_not_of("0123456789", at + 10) - (at + 10));
      write_file_atomically(jobs_file, merge_job);
      std::printf("submitted: %s", out.c_str());
      std::fflush(stdout);
    }
    for (std::string reason; !(reason = queue_reason(merge_job)).empty();) {
      // A shard that failed leaves the merge waiting for ever (afterok): cancel it and say why.
      if (reason.find("DependencyNeverSatisfied") != std::string::npos) {
        shell("scancel " + merge_job + " 2>/dev/null");
        fs::remove(jobs_file);  // the next `learn run` submits the round's shards again; they resume
        std::string tails;
        for (const auto& entry : fs::directory_iterator(r.work_dir)) {
          if (entry.path().extension() != ".out") continue;
          const auto text = read_whole_file(entry.path().string());
          if (text && !text->empty()) tails += "\n  " + entry.path().filename().string() + ": " + text->substr(text->rfind('\n', text->size() - 2) + 1);
        }
        throw Error("a Slurm shard of " + r.work_dir + " failed, so its merge job " + merge_job + " was cancelled; its output:" + tails);
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(c.slurm_poll_seconds));
    }
    if (fs::exists(merged)) {
      copy_file_atomically(merged, r.db_path);
      return;
    }
    std::printf("Slurm merge job %s ended without %s; submitting the round's shards again\n", merge_job.c_str(), merged.c_str());
  }
  throw Error("the Slurm jobs of " + r.work_dir + " ended twice without a merged database; see the *.out files there");
}

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
    o.run_rows = [&c, mufric](const RoundRuns& r) { run_rows_on_slurm(r, c, mufric); };
  }
  for (;;) {
    const LearnReport r = learn_rounds(c.directory, o);
    if (r.stop == LearnStop::budget_spent || c.follow_seconds <= 0.0) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(c.follow_seconds));
  }
}

void print_status(const std::string& directory) {
  const LearnState s = read_learn_state(directory);
  const LearnSetup& u = s.setup;
  std::printf("learner %s\n  database %s\n  serves %s (now version %s)\n  reads %s\n", directory.c_str(), u.db.c_str(),
              u.served_model.c_str(), file_version(u.served_model).c_str(), u.log.c_str());
  std::printf("  rounds of at most %lld runs; rests below %.3g %% of queries uncertain or outside\n", u.round_samples,
              100.0 * u.rest_below);
  std::printf("  spent %.3g of %.3g core-hours\n", s.spent_core_seconds / 3600.0, u.budget_core_hours);
  for (const LearnRound& r : s.rounds) {
    char share[32] = "share unknown";
    if (r.uncertain_share >= 0.0) std::snprintf(share, sizeof share, "%.3g %% of queries", 100.0 * r.uncertain_share);
    std::printf("  round %d: %s; %lld logged rows (%s), plan rows %lld-%lld, %.3g core-hours", r.number, to_string(r.step),
                r.logged_rows, share, r.first_plan_row, r.end_plan_row - 1, r.run_core_seconds / 3600.0);
    if (r.step == LearnStep::done) {
      std::printf("; %s %s: %s", r.gate.publish ? "published" : "kept aside", r.version.empty() ? "(no candidate)" : r.version.c_str(),
                  r.gate.reason.c_str());
      if (r.quarantined > 0) std::printf("; its %lld samples quarantined (failed, with the reason)", r.quarantined);
    }
    std::printf("\n");
  }
  std::printf("  versions kept (mufric learn rollback %s VERSION):\n", directory.c_str());
  for (const auto& v : s.served) std::printf("    %s  %s  %s\n", v.version.c_str(), v.utc.c_str(), v.how.c_str());
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
  status->callback([status_dir] { print_status(*status_dir); });

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
