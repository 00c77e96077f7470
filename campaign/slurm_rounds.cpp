#include "campaign/slurm_rounds.hpp"

#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <utility>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/wording.hpp"

namespace mufric {
namespace {

// How long squeue may fail to answer (controller down or restarting) before the learner stops waiting.
constexpr double kSlurmSilenceLimitSeconds = 1800.0;

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

void say(const SlurmRoundOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

}  // namespace

void run_round_on_slurm(const RoundRuns& r, const SlurmRoundOptions& c) {
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
        say(c, text_printf("squeue does not answer about job %s (%s); asking again every %g s", job.c_str(),
                           out.substr(0, out.find('\n')).c_str(), c.poll_seconds));
      }
      if (std::chrono::duration<double>(now - silent_since).count() > kSlurmSilenceLimitSeconds) {
        throw Error("squeue has not answered about job " + job + " for " + std::to_string(static_cast<int>(kSlurmSilenceLimitSeconds)) +
                    " s (" + out.substr(0, out.find('\n')) + "); the job may still run: `mufric learn run` again waits for it");
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(c.poll_seconds));
    }
  };
  for (int attempt = 0; attempt < 2; ++attempt) {
    std::string merge_job;
    if (const auto text = read_whole_file(jobs_file)) merge_job = *text;
    if (merge_job.empty() || (queue_reason(merge_job).empty() && !fs::exists(merged))) {
      fs::remove(merged);
      for (int i = 0; i < c.tasks; ++i) {
        const std::string shard = r.work_dir + "/shard-" + std::to_string(i) + ".h5";
        if (!fs::exists(shard)) copy_file_atomically(r.db_path, shard);
      }
      // dataset-array.sbatch splits MUFRIC_RUN_ARGS on spaces (no quotes): a path with a space cannot pass.
      const std::string simulator = c.simulator.empty() ? "" : fs::absolute(c.simulator).string();
      if (simulator.find_first_of(" \t'\"") != std::string::npos) throw Error("--simulator " + simulator + ": a path with spaces or quotes cannot pass to the Slurm tasks");
      const std::string run_args = simulator.empty() ? "" : "--simulator " + simulator;
      const auto [out, status] = shell("MUFRIC=" + quoted(c.mufric) + " MUFRIC_RUN_ARGS=" + quoted(run_args) + " bash " +
                                       quoted(c.submit_script) + " " + quoted(r.db_path) + " " + quoted(r.work_dir) + " " +
                                       std::to_string(c.tasks) + " " + c.sbatch_args + " 2>&1");
      const auto at = out.find("merge job ");
      if (status != 0 || at == std::string::npos) throw Error("Slurm submission failed: " + out);
      merge_job = out.substr(at + 10, out.find_first_not_of("0123456789", at + 10) - (at + 10));
      write_file_atomically(jobs_file, merge_job);
      say(c, "submitted: " + out.substr(0, out.find_last_not_of('\n') + 1));
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
      std::this_thread::sleep_for(std::chrono::duration<double>(c.poll_seconds));
    }
    if (fs::exists(merged)) {
      copy_file_atomically(merged, r.db_path);
      return;
    }
    say(c, "Slurm merge job " + merge_job + " ended without " + merged + "; submitting the round's shards again");
  }
  throw Error("the Slurm jobs of " + r.work_dir + " ended twice without a merged database; see the *.out files there");
}

}  // namespace mufric
