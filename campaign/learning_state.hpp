#pragma once
// The learner's state (campaign/learning.hpp): what it works on, its rounds and the versions it kept,
// in DIR/learn.json, written atomically after every step; and the lock that keeps one learner a
// directory.
#include <string>
#include <vector>

#include "campaign/learning_gate.hpp"

namespace mufric {

// A round's steps in their order (campaign/learning.hpp's 1-5: planning is part of `run`); a round
// records the step it is at, so that a resumed learner carries on there. Spelled in learn.json as
// "run", "train", "gate", "done".
enum class LearnStep { run, train, gate, done };
const char* to_string(LearnStep step);

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

// One round's record in DIR/learn.json.
struct LearnRound {
  int number = 0;
  LearnStep step = LearnStep::run;
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

// DIR/learn.json.
std::string learn_state_path(const std::string& directory);
LearnState read_learn_state(const std::string& directory);
void write_learn_state(const std::string& directory, const LearnState& s);
// `mufric learn status`: the setup, the spend, each round with its gate's decision, the versions kept.
std::string learn_status_text(const std::string& directory);

// One learner per directory: DIR/lock held (flock) while it lives; an Error naming the directory when
// another learner holds it. Closing releases it, as does the process's death.
class LearnerLock {
 public:
  explicit LearnerLock(const std::string& dir);
  ~LearnerLock();
  LearnerLock(const LearnerLock&) = delete;
  LearnerLock& operator=(const LearnerLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace mufric
