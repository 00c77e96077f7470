#include "campaign/learning_state.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <utility>

#include <nlohmann/json.hpp>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/wording.hpp"

namespace mufric {

namespace {

// A step's word in learn.json and in `learn status`, one table for both.
constexpr std::pair<LearnStep, const char*> kStepWords[] = {
    {LearnStep::run, "run"}, {LearnStep::train, "train"}, {LearnStep::gate, "gate"}, {LearnStep::done, "done"}};

}  // namespace

const char* to_string(LearnStep step) {
  for (const auto& [value, word] : kStepWords) {
    if (value == step) return word;
  }
  return "?";
}

// A word no step has is an error (read_learn_state names the file), not a silent "run".
void to_json(nlohmann::json& j, LearnStep step) { j = to_string(step); }
void from_json(const nlohmann::json& j, LearnStep& step) {
  const auto word = j.get<std::string>();
  for (const auto& [value, name] : kStepWords) {
    if (word == name) {
      step = value;
      return;
    }
  }
  throw Error("a round's step '" + word + "' is none of run, train, gate, done");
}

// The state file's records, each key its member's name (nlohmann/json's macros; at namespace scope,
// where argument-dependent lookup finds them).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(LearnSetup, db, served_model, log, round_samples, budget_core_hours, rest_below,
                                   grow_coverage, seed, restarts)
// With defaults: a state written before the measurements' counts reads them as 0.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GateDecision, publish, reason, old_points, served_loo_rmse, candidate_loo_rmse,
                                                allowed_loo_rmse, new_points, new_covered, grid_certified, measurements,
                                                measurements_covered, values_refused)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(LearnRound, number, step, first_plan_row, end_plan_row, logged_rows, uncertain_share,
                                                run_core_seconds, candidate, gate, quarantined, version, finished_utc)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(LearnState::Served, version, utc, how)

namespace fs = std::filesystem;
using nlohmann::json;


std::string learn_state_path(const std::string& directory) { return (fs::path(directory) / "learn.json").string(); }

void write_learn_state(const std::string& dir, const LearnState& s) {
  const json j = {{"format", "mufric learn state 1"},
                  {"setup", s.setup},
                  {"log_offset", s.log_offset},
                  {"log_file_id", s.log_file_id},
                  {"queries_seen", s.queries_seen},
                  {"spent_core_seconds", s.spent_core_seconds},
                  {"rounds", s.rounds},
                  {"served", s.served}};
  write_file_atomically(learn_state_path(dir), j.dump(2) + "\n");
}

LearnState read_learn_state(const std::string& directory) {
  const std::string path = learn_state_path(directory);
  const auto text = read_whole_file(path);
  if (!text) throw Error(path + ": no learner here (start one with mufric learn init)");
  try {
    const json j = json::parse(*text);
    LearnState s;
    j.at("setup").get_to(s.setup);
    j.at("log_offset").get_to(s.log_offset);
    s.log_file_id = j.value("log_file_id", 0LL);  // absent in states written before the log was renamed when full
    j.at("queries_seen").get_to(s.queries_seen);
    j.at("spent_core_seconds").get_to(s.spent_core_seconds);
    j.at("rounds").get_to(s.rounds);
    j.at("served").get_to(s.served);
    return s;
  } catch (const json::exception& e) {
    throw Error(path + ": not a learner's state (" + e.what() + ")");
  } catch (const Error& e) {
    throw Error(path + ": not a learner's state (" + e.what() + ")");
  }
}

std::string learn_status_text(const std::string& directory) {
  const LearnState s = read_learn_state(directory);
  const LearnSetup& u = s.setup;
  std::string out = text_printf("learner %s\n  database %s\n  serves %s (now version %s)\n  reads %s\n", directory.c_str(),
                                u.db.c_str(), u.served_model.c_str(), file_version(u.served_model).c_str(), u.log.c_str());
  out += text_printf("  rounds of at most %lld runs; rests below %.3g %% of queries uncertain or outside\n", u.round_samples,
                     100.0 * u.rest_below);
  out += text_printf("  spent %.3g of %.3g core-hours\n", s.spent_core_seconds / 3600.0, u.budget_core_hours);
  for (const LearnRound& r : s.rounds) {
    const std::string share =
        r.uncertain_share >= 0.0 ? text_printf("%.3g %% of queries", 100.0 * r.uncertain_share) : "share unknown";
    out += text_printf("  round %d: %s; %lld logged rows (%s), plan rows %lld-%lld, %.3g core-hours", r.number, to_string(r.step),
                       r.logged_rows, share.c_str(), r.first_plan_row, r.end_plan_row - 1, r.run_core_seconds / 3600.0);
    if (r.step == LearnStep::done) {
      out += text_printf("; %s %s: %s", r.gate.publish ? "published" : "kept aside",
                         r.version.empty() ? "(no candidate)" : r.version.c_str(), r.gate.reason.c_str());
      if (r.quarantined > 0) out += text_printf("; its %lld samples quarantined (failed, with the reason)", r.quarantined);
    }
    out += "\n";
  }
  out += "  versions kept (mufric learn rollback " + directory + " VERSION):\n";
  for (const auto& v : s.served) out += "    " + v.version + "  " + v.utc + "  " + v.how + "\n";
  return out;
}

LearnerLock::LearnerLock(const std::string& dir) {
  const std::string path = (fs::path(dir) / "lock").string();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(path + ": cannot open the learner's lock");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    throw Error(dir + ": another learner is working in this directory (its lock " + path + " is held)");
  }
}

LearnerLock::~LearnerLock() { ::close(fd_); }

}  // namespace mufric
