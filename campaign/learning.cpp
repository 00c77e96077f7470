#include "campaign/learning.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "campaign/campaign_summary.hpp"
#include "campaign/refine.hpp"
#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/version.hpp"
#include "surrogate/gp_training.hpp"
#include "surrogate/model_file.hpp"

namespace mufric {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kStateFile = "learn.json";
constexpr double kSecondsPerHour = 3600.0;
constexpr double kCoverageLevel = 0.95;
constexpr double kZ95 = 1.959963984540054;

std::string state_path(const std::string& dir) { return (fs::path(dir) / kStateFile).string(); }
std::string version_path(const std::string& dir, const std::string& version) {
  return (fs::path(dir) / "versions" / (version + ".h5")).string();
}

// ---- the state file -------------------------------------------------------------------------

json to_json(const LearnSetup& s) {
  return {{"db", s.db},         {"served_model", s.served_model},     {"log", s.log},
          {"round_samples", s.round_samples}, {"budget_core_hours", s.budget_core_hours},
          {"rest_below", s.rest_below},       {"grow_coverage", s.grow_coverage},
          {"seed", s.seed},                   {"restarts", s.restarts}};
}
LearnSetup setup_from_json(const json& j) {
  LearnSetup s;
  s.db = j.at("db");
  s.served_model = j.at("served_model");
  s.log = j.at("log");
  s.round_samples = j.at("round_samples");
  s.budget_core_hours = j.at("budget_core_hours");
  s.rest_below = j.at("rest_below");
  s.grow_coverage = j.at("grow_coverage");
  s.seed = j.at("seed");
  s.restarts = j.at("restarts");
  return s;
}
json to_json(const GateDecision& g) {
  return {{"publish", g.publish},
          {"reason", g.reason},
          {"old_points", g.old_points},
          {"served_loo_rmse", g.served_loo_rmse},
          {"candidate_loo_rmse", g.candidate_loo_rmse},
          {"allowed_loo_rmse", g.allowed_loo_rmse},
          {"new_points", g.new_points},
          {"new_covered", g.new_covered},
          {"grid_certified", g.grid_certified}};
}
GateDecision gate_from_json(const json& j) {
  GateDecision g;
  g.publish = j.at("publish");
  g.reason = j.at("reason");
  g.old_points = j.at("old_points");
  g.served_loo_rmse = j.at("served_loo_rmse");
  g.candidate_loo_rmse = j.at("candidate_loo_rmse");
  g.allowed_loo_rmse = j.at("allowed_loo_rmse");
  g.new_points = j.at("new_points");
  g.new_covered = j.at("new_covered");
  g.grid_certified = j.at("grid_certified");
  return g;
}
json to_json(const LearnRound& r) {
  return {{"number", r.number},
          {"step", r.step},
          {"first_plan_row", r.first_plan_row},
          {"end_plan_row", r.end_plan_row},
          {"logged_rows", r.logged_rows},
          {"uncertain_share", r.uncertain_share},
          {"run_core_seconds", r.run_core_seconds},
          {"candidate", r.candidate},
          {"gate", to_json(r.gate)},
          {"version", r.version},
          {"finished_utc", r.finished_utc}};
}
LearnRound round_from_json(const json& j) {
  LearnRound r;
  r.number = j.at("number");
  r.step = j.at("step");
  r.first_plan_row = j.at("first_plan_row");
  r.end_plan_row = j.at("end_plan_row");
  r.logged_rows = j.at("logged_rows");
  r.uncertain_share = j.at("uncertain_share");
  r.run_core_seconds = j.at("run_core_seconds");
  r.candidate = j.at("candidate");
  r.gate = gate_from_json(j.at("gate"));
  r.version = j.at("version");
  r.finished_utc = j.at("finished_utc");
  return r;
}

void write_state(const std::string& dir, const LearnState& s) {
  json rounds = json::array(), served = json::array();
  for (const auto& r : s.rounds) rounds.push_back(to_json(r));
  for (const auto& v : s.served) served.push_back({{"version", v.version}, {"utc", v.utc}, {"how", v.how}});
  const json j = {{"format", "mufric learn state 1"},
                  {"setup", to_json(s.setup)},
                  {"log_offset", s.log_offset},
                  {"queries_seen", s.queries_seen},
                  {"spent_core_seconds", s.spent_core_seconds},
                  {"rounds", rounds},
                  {"served", served}};
  write_file_atomically(state_path(dir), j.dump(2) + "\n");
}

// ---- one learner per directory --------------------------------------------------------------

class DirectoryLock {
 public:
  explicit DirectoryLock(const std::string& dir) {
    const std::string path = (fs::path(dir) / "lock").string();
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw Error(path + ": cannot open the learner's lock");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw Error(dir + ": another learner is working in this directory (its lock " + path + " is held)");
    }
  }
  ~DirectoryLock() { ::close(fd_); }  // closing releases the lock, as does the process's death
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

 private:
  int fd_ = -1;
};

// ---- the server's log -----------------------------------------------------------------------

// The rows the server appended since `offset` (whole lines only: a line being written is left for
// the next round), as a CSV with the file's header; the new offset. A log shorter than the offset
// was started afresh (renamed away by an operator): it is read from its start.
struct NewLogRows {
  std::string csv;  // header + the new lines ("" when the log does not exist)
  long long rows = 0;
  long long end_offset = 0;
};
NewLogRows read_new_log_rows(const std::string& path, long long offset) {
  NewLogRows out;
  out.end_offset = offset;
  const auto text = read_whole_file(path);
  if (!text) return out;
  const auto header_end = text->find('\n');
  if (header_end == std::string::npos) return out;
  const long long size = static_cast<long long>(text->size());
  const long long start = offset > size || offset <= static_cast<long long>(header_end) ? static_cast<long long>(header_end) + 1 : offset;
  const auto last_newline = text->rfind('\n');
  const long long end = static_cast<long long>(last_newline) + 1;
  out.end_offset = std::max(start, end);
  if (end <= start) return out;
  out.csv = text->substr(0, header_end + 1) + text->substr(static_cast<size_t>(start), static_cast<size_t>(end - start));
  out.rows = static_cast<long long>(std::count(out.csv.begin(), out.csv.end(), '\n')) - 1;
  return out;
}

// The model's query count from the log's NAME.outside.json beside it (−1 when absent or unreadable:
// the server writes it at most once a second, atomically).
long long logged_query_count(const std::string& log_path) {
  fs::path p(log_path);
  p.replace_extension(".outside.json");
  const auto text = read_whole_file(p.string());
  if (!text) return -1;
  try {
    return json::parse(*text).at("queries").get<long long>();
  } catch (const std::exception&) {
    return -1;
  }
}

// ---- training as `train` does it ------------------------------------------------------------

// The served model's policies (extrapolation, μ range) carry over; its grids are built to `fast`.
GaussianProcess train_candidate(const Dataset& db, const std::string& db_path, const FrictionModel& served,
                                const LearnSetup& setup, const FastEvaluatorOptions& fast) {
  TrainingSet data = training_set(db, db_path);
  data.description = campaign_summary(db);
  GpTrainingOptions training;
  training.restarts = setup.restarts;
  training.seed = setup.seed;
  GaussianProcess gp = fit_campaign_gp(data, training);
  gp.set_default_extrapolation(served.default_extrapolation());
  gp.set_mu_range(served.mu_min(), served.mu_max());
  attach_fast_evaluators(gp, fast, build_kept_fast_evaluator);
  return gp;
}

std::unique_ptr<GaussianProcess> load_gp(const std::string& path, const std::string& role) {
  std::unique_ptr<FrictionModel> model = load_model_isolated(path);
  auto* gp = dynamic_cast<GaussianProcess*>(model.get());
  if (gp == nullptr) {
    throw Error(path + ": the " + role + " is a " + std::string(model->kind()) +
                " model; the learner retrains a campaign's GP (a calibrated model is recalibrated by mufric calibrate)");
  }
  model.release();
  return std::unique_ptr<GaussianProcess>(gp);
}

void say(const LearnRunOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

__attribute__((format(printf, 1, 2))) std::string format(const char* pattern, ...) {
  char text[1024];
  va_list arguments;
  va_start(arguments, pattern);
  std::vsnprintf(text, sizeof text, pattern, arguments);
  va_end(arguments);
  return text;
}

// Keeps the served file's bytes as DIR/versions/<version>.h5 (once) and records it.
void keep_version(const std::string& dir, LearnState& s, const std::string& file, const std::string& how) {
  const std::string version = file_version(file);
  const std::string kept = version_path(dir, version);
  if (!fs::exists(kept)) {
    const auto bytes = read_whole_file(file);
    if (!bytes) throw Error(file + ": cannot read it to keep its version");
    write_file_atomically(kept, *bytes);
  }
  if (!s.served.empty() && s.served.back().version == version) return;  // a resumed step, already recorded
  s.served.push_back({version, utc_timestamp(), how});
}

// Replaces the served file by `source`'s bytes in one rename: a reader (the server's reload) sees
// the old file or the new one, never a part (the temporary's name does not end in .h5).
void publish_file(const std::string& source, const std::string& served) {
  const auto bytes = read_whole_file(source);
  if (!bytes) throw Error(source + ": cannot read it to publish");
  write_file_atomically(served, *bytes);
}

// Plan rows of the database no sample answers, as [first, end): a kill after the picks were written
// and before the state recorded them leaves them there, and they are the round's.
std::pair<long long, long long> pending_rows(const Dataset& db) {
  std::vector<bool> answered(static_cast<size_t>(db.plan.rows()), false);
  for (const long long row : db.plan_index) {
    if (row >= 0 && row < db.plan.rows()) answered[static_cast<size_t>(row)] = true;
  }
  long long first = db.plan.rows();
  for (long long row = 0; row < db.plan.rows(); ++row) {
    if (!answered[static_cast<size_t>(row)]) {
      first = row;
      break;
    }
  }
  return {first, db.plan.rows()};
}

// The mean core-seconds of a sample so far (the database's micro_wall_seconds, else the learner's
// own count), for how many runs the budget still allows; 0 when nothing is known.
double mean_sample_core_seconds(const Dataset& db, const LearnState& s, int threads_per_job) {
  const auto it = db.diagnostics.find("micro_wall_seconds");
  double sum = 0.0;
  long long n = 0;
  if (it != db.diagnostics.end()) {
    for (Eigen::Index i = 0; i < it->second.size(); ++i) {
      if (std::isfinite(it->second(i))) {
        sum += it->second(i);
        ++n;
      }
    }
  }
  if (n > 0) return threads_per_job * sum / static_cast<double>(n);
  long long runs = 0;
  for (const auto& r : s.rounds) runs += r.end_plan_row - r.first_plan_row;
  return runs > 0 ? s.spent_core_seconds / static_cast<double>(runs) : 0.0;
}

// Step 1–2: a new round planned, or why not.
enum class PlanOutcome { planned, resting, budget_spent };
PlanOutcome plan_round(const std::string& dir, LearnState& s, const LearnRunOptions& o) {
  const LearnSetup& setup = s.setup;
  const double budget = setup.budget_core_hours * kSecondsPerHour;
  if (s.spent_core_seconds >= budget) return PlanOutcome::budget_spent;
  Dataset db = read_dataset_isolated(setup.db);
  LearnRound round;
  round.number = static_cast<int>(s.rounds.size()) + 1;
  if (const auto [first, end] = pending_rows(db); first < end) {
    say(o, format("round %d: the database holds %lld planned rows not yet run; they are this round's", round.number, end - first));
    round.first_plan_row = first;
    round.end_plan_row = end;
    round.step = "run";
    s.rounds.push_back(round);
    write_state(dir, s);
    return PlanOutcome::planned;
  }
  const NewLogRows logged = read_new_log_rows(setup.log, s.log_offset);
  const long long queries = logged_query_count(setup.log);
  const long long new_queries = queries < 0 ? -1 : (s.queries_seen >= 0 && queries >= s.queries_seen ? queries - s.queries_seen : queries);
  round.logged_rows = logged.rows;
  // At most 1: the counts restart with a reloaded model's box while its log goes on.
  round.uncertain_share =
      new_queries > 0 ? std::min(1.0, static_cast<double>(logged.rows) / static_cast<double>(new_queries)) : -1.0;
  s.log_offset = logged.end_offset;
  s.queries_seen = queries;
  const bool quiet = logged.rows == 0 || (round.uncertain_share >= 0.0 && round.uncertain_share < setup.rest_below);
  if (quiet) {
    say(o, round.uncertain_share >= 0.0
               ? format("resting: %lld of %lld queries logged as uncertain or outside since the last look (%.2g %%, below %.2g %%)",
                        logged.rows, new_queries, 100.0 * round.uncertain_share, 100.0 * setup.rest_below)
               : format("resting: no query logged as uncertain or outside since the last look (%s)", setup.log.c_str()));
    write_state(dir, s);
    return PlanOutcome::resting;
  }
  // The round's batch: its samples, within what the budget still pays for at the mean cost so far.
  long long batch = setup.round_samples;
  if (const double cost = mean_sample_core_seconds(db, s, o.threads_per_job); cost > 0.0) {
    batch = std::min(batch, std::max(1LL, static_cast<long long>((budget - s.spent_core_seconds) / cost)));
  }
  const std::string rows_path = (fs::path(dir) / ("round-" + std::to_string(round.number) + "-logged.csv")).string();
  write_file_atomically(rows_path, logged.csv);
  const Eigen::MatrixXd rows = logged_candidates(rows_path, db.inputs);
  const BoxGrowth growth = grow_plan_box(db, rows, setup.grow_coverage, rows_path, "mufric learn");
  if (growth.grown) say(o, "round " + std::to_string(round.number) + ": " + growth.record);
  const TrainingSet data = training_set(db, setup.db);
  GpTrainingOptions training;
  training.restarts = setup.restarts;
  training.seed = setup.seed + static_cast<unsigned long long>(round.number);
  const GaussianProcess gp = fit_campaign_gp(data, training);
  // The learner serves where the queries are: a pick's worth is the variance it removes there.
  const PickOptions picking{4096, 512, setup.seed, true};
  const std::vector<RefinePick> picks = append_refinement_picks(db, gp, data, rows, picking, round.number, static_cast<int>(batch));
  round.first_plan_row = db.plan.rows() - static_cast<long long>(picks.size());
  round.end_plan_row = db.plan.rows();
  write_dataset(setup.db, db);
  round.step = "run";
  s.rounds.push_back(round);
  write_state(dir, s);
  say(o, format("round %d: %lld logged rows (%s of the queries); planned %zu runs, plan rows %lld-%lld", round.number, logged.rows,
                round.uncertain_share >= 0.0 ? format("%.2g %%", 100.0 * round.uncertain_share).c_str() : "share unknown",
                picks.size(), round.first_plan_row, round.end_plan_row - 1));
  return PlanOutcome::planned;
}

// The core-seconds of the runs of plan rows [first, end) as the database records them (the
// micro-model's micro_wall_seconds), for runs made by another engine; 0 where not recorded.
double recorded_core_seconds(const Dataset& db, long long first, long long end, int threads_per_job) {
  const auto it = db.diagnostics.find("micro_wall_seconds");
  if (it == db.diagnostics.end()) return 0.0;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < db.size(); ++i) {
    const long long row = db.plan_index[static_cast<size_t>(i)];
    if (row >= first && row < end && std::isfinite(it->second(i))) sum += it->second(i);
  }
  return sum * threads_per_job;
}

// Step 3: the round's rows run (resumes: generate_dataset skips rows already answered), then the
// database's samples in plan-row order, whatever order the engine finished them in: the same runs
// train the same model, from the local pool or a Slurm array.
void run_round(const std::string& dir, LearnState& s, const LearnRunOptions& o) {
  LearnRound& round = s.rounds.back();
  if (o.run_rows) {
    const std::string work = (fs::path(dir) / ("round-" + std::to_string(round.number) + "-runs")).string();
    fs::create_directories(work);
    say(o, format("round %d: plan rows %lld-%lld handed to the engine (%s)", round.number, round.first_plan_row,
                  round.end_plan_row - 1, work.c_str()));
    o.run_rows({s.setup.db, work, round.first_plan_row, round.end_plan_row});
    const double core_seconds =
        recorded_core_seconds(read_dataset_isolated(s.setup.db), round.first_plan_row, round.end_plan_row, o.threads_per_job);
    s.spent_core_seconds += core_seconds - round.run_core_seconds;
    round.run_core_seconds = core_seconds;
  } else {
    const Dataset db = read_dataset_isolated(s.setup.db);
    const SampleEvaluator evaluate = o.make_evaluator(db);
    GenerationOptions generation;
    generation.jobs = o.jobs;
    generation.on_sample = [&](const GenerationProgress& p) {
      // The micro-model's own time where it reports it (the budget is what the runs cost), else the wall time.
      double seconds = p.sample_seconds;
      if (p.outcome != nullptr) {
        if (const auto it = p.outcome->diagnostics.find("micro_wall_seconds"); it != p.outcome->diagnostics.end()) seconds = it->second;
      }
      const double core_seconds = seconds * o.threads_per_job;
      round.run_core_seconds += core_seconds;
      s.spent_core_seconds += core_seconds;
      write_state(dir, s);
      say(o, format("round %d: sample %lld/%lld (plan row %lld) %s in %.1f s; spent %.3g of %.3g core-hours", round.number,
                    p.finished, p.to_run, p.plan_row,
                    p.outcome && p.outcome->converged ? format("mu %.5f", p.outcome->mu).c_str() : "failed", p.sample_seconds,
                    s.spent_core_seconds / kSecondsPerHour, s.setup.budget_core_hours));
    };
    generate_dataset(db, s.setup.db, evaluate, generation);
  }
  MergeReport merged;
  const Dataset ordered = merge_datasets({s.setup.db}, false, merged);
  if (merged.plan_rows_missing > 0) {
    throw Error(s.setup.db + ": " + std::to_string(merged.plan_rows_missing) + " plan rows of round " + std::to_string(round.number) +
                " were not run; run `mufric learn run` again to resume them");
  }
  write_dataset(s.setup.db, ordered);
  round.step = "train";
  write_state(dir, s);
}

// Step 4: the candidate trained and saved.
void train_round(const std::string& dir, LearnState& s, const LearnRunOptions& o) {
  LearnRound& round = s.rounds.back();
  const std::unique_ptr<GaussianProcess> served = load_gp(s.setup.served_model, "served model");
  const Dataset db = read_dataset_isolated(s.setup.db);
  say(o, format("round %d: training on %lld samples", round.number, static_cast<long long>(db.size())));
  const GaussianProcess candidate = train_candidate(db, s.setup.db, *served, s.setup, o.fast);
  round.candidate = (fs::path(dir) / "candidates" / ("round-" + std::to_string(round.number) + ".h5")).string();
  save_model(round.candidate, candidate);
  round.version = file_version(round.candidate);
  round.step = "gate";
  write_state(dir, s);
}

// Step 5: gated, and published or kept aside.
void gate_round(const std::string& dir, LearnState& s, const LearnRunOptions& o) {
  LearnRound& round = s.rounds.back();
  const std::unique_ptr<GaussianProcess> served = load_gp(s.setup.served_model, "served model");
  const std::unique_ptr<GaussianProcess> candidate = load_gp(round.candidate, "candidate");
  round.gate = gate_candidate(*served, *candidate, o.fast);
  if (round.gate.publish) {
    keep_version(dir, s, round.candidate, "published by round " + std::to_string(round.number));
    publish_file(round.candidate, s.setup.served_model);
  }
  round.step = "done";
  round.finished_utc = utc_timestamp();
  write_state(dir, s);
  say(o, format("round %d: %s %s: %s", round.number, round.gate.publish ? "published" : "kept aside", round.version.c_str(),
                round.gate.reason.c_str()));
}

}  // namespace

double binomial_lower_tail(long long k, long long n, double p) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  double sum = 0.0;
  for (long long i = 0; i <= k; ++i) {
    const double log_pmf = std::lgamma(static_cast<double>(n) + 1.0) - std::lgamma(static_cast<double>(i) + 1.0) -
                           std::lgamma(static_cast<double>(n - i) + 1.0) + static_cast<double>(i) * std::log(p) +
                           static_cast<double>(n - i) * std::log1p(-p);
    sum += std::exp(log_pmf);
  }
  return std::min(sum, 1.0);
}

GateDecision gate_candidate(const GaussianProcess& served, const GaussianProcess& candidate, const FastEvaluatorOptions& tolerances) {
  GateDecision g;
  if (!same_input_space(served.inputs(), candidate.inputs())) {
    // The box grew: the inputs must still be the same names in the same order.
    bool same_names = served.inputs().size() == candidate.inputs().size();
    for (size_t j = 0; same_names && j < served.inputs().size(); ++j) same_names = served.inputs()[j].name == candidate.inputs()[j].name;
    if (!same_names) {
      g.reason = "the candidate's inputs are not the served model's";
      return g;
    }
  }
  const auto& old_state = served.state();
  const auto& new_state = candidate.state();
  const LeaveOneOut old_loo = leave_one_out_points(old_state), new_loo = leave_one_out_points(new_state);
  if (old_loo.error.size() == 0 || new_loo.error.size() == 0) {
    g.reason = "leave-one-out could not be computed (a factor could not be inverted)";
    return g;
  }
  // The candidate's rows at the served version's points (the same samples: same SI coordinates).
  std::map<std::vector<double>, Eigen::Index> candidate_row;
  for (Eigen::Index i = 0; i < new_state.x_train.rows(); ++i) {
    const Eigen::VectorXd row = new_state.x_train.row(i);
    candidate_row.emplace(std::vector<double>(row.data(), row.data() + row.size()), i);
  }
  std::vector<bool> is_old(static_cast<size_t>(new_state.x_train.rows()), false);
  double old_sq = 0.0, new_sq = 0.0;
  for (Eigen::Index i = 0; i < old_state.x_train.rows(); ++i) {
    const Eigen::VectorXd row = old_state.x_train.row(i);
    const auto it = candidate_row.find(std::vector<double>(row.data(), row.data() + row.size()));
    if (it == candidate_row.end()) continue;
    is_old[static_cast<size_t>(it->second)] = true;
    ++g.old_points;
    old_sq += old_loo.error(i) * old_loo.error(i);
    new_sq += new_loo.error(it->second) * new_loo.error(it->second);
  }
  if (g.old_points < old_state.x_train.rows()) {
    g.reason = format("the candidate was not trained on all the served version's points (%lld of %lld found): another database",
                      g.old_points, static_cast<long long>(old_state.x_train.rows()));
    return g;
  }
  const double n = static_cast<double>(g.old_points);
  g.served_loo_rmse = std::sqrt(old_sq / n);
  g.candidate_loo_rmse = std::sqrt(new_sq / n);
  g.allowed_loo_rmse = g.served_loo_rmse * (1.0 + kGateRmseSlack / std::sqrt(2.0 * n));
  for (Eigen::Index i = 0; i < new_state.x_train.rows(); ++i) {
    if (is_old[static_cast<size_t>(i)]) continue;
    ++g.new_points;
    if (std::abs(new_loo.error(i)) <= kZ95 * new_loo.std(i)) ++g.new_covered;
  }
  const FastEvaluator* served_grid = served.fast_evaluator();
  const FastEvaluator* candidate_grid = candidate.fast_evaluator();
  const bool served_certified = served_grid != nullptr && served_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance);
  g.grid_certified = !served_certified || (candidate_grid != nullptr && candidate_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance));
  const std::string figures = format("leave-one-out RMSE on the served version's %lld points %.3g (served %.3g, at most %.3g); "
                                     "%lld of %lld new points inside their 95 %% interval",
                                     g.old_points, g.candidate_loo_rmse, g.served_loo_rmse, g.allowed_loo_rmse, g.new_covered, g.new_points);
  if (g.new_points == 0) {
    g.reason = "the round added no converged point; " + figures;
  } else if (g.candidate_loo_rmse > g.allowed_loo_rmse) {
    g.reason = "worse on what the served version knew: " + figures;
  } else if (binomial_lower_tail(g.new_covered, g.new_points, kCoverageLevel) < kGateCoverageSignificance) {
    g.reason = format("its interval misses its new points more often than a 95 %% interval may (binomial p < %g): ",
                      kGateCoverageSignificance) + figures;
  } else if (!g.grid_certified) {
    g.reason = "its fast evaluator does not meet the tolerances the served one met; " + figures;
  } else {
    g.publish = true;
    g.reason = "no worse: " + figures;
  }
  return g;
}

std::string file_version(const std::string& path) { return sha256_file(path).substr(0, 16); }

void learn_init(const std::string& directory, const LearnSetup& setup) {
  if (fs::exists(state_path(directory))) throw Error(directory + ": already holds a learner (" + state_path(directory) + ")");
  if (setup.round_samples < 1) throw Error("round samples: must be at least 1");
  if (!(setup.budget_core_hours > 0.0)) throw Error("budget core-hours: must be positive");
  if (!(setup.rest_below >= 0.0 && setup.rest_below < 1.0)) throw Error("rest below: must lie in [0, 1)");
  const Dataset db = read_dataset_isolated(setup.db);
  if (db.plan.rows() == 0) throw Error(setup.db + ": not a campaign database (no plan rows); start with mufric dataset plan and run");
  if (fs::path(setup.served_model).extension() != ".h5") throw Error(setup.served_model + ": a served model's file name ends in .h5");
  load_gp(setup.served_model, "served model");
  fs::create_directories(fs::path(directory) / "versions");
  fs::create_directories(fs::path(directory) / "candidates");
  LearnState s;
  s.setup = setup;
  s.setup.db = fs::absolute(setup.db).string();
  s.setup.served_model = fs::absolute(setup.served_model).string();
  s.setup.log = fs::absolute(setup.log).string();
  keep_version(directory, s, s.setup.served_model, "found");
  write_state(directory, s);
}

LearnState read_learn_state(const std::string& directory) {
  const std::string path = state_path(directory);
  const auto text = read_whole_file(path);
  if (!text) throw Error(path + ": no learner here (start one with mufric learn init)");
  try {
    const json j = json::parse(*text);
    LearnState s;
    s.setup = setup_from_json(j.at("setup"));
    s.log_offset = j.at("log_offset");
    s.queries_seen = j.at("queries_seen");
    s.spent_core_seconds = j.at("spent_core_seconds");
    for (const auto& r : j.at("rounds")) s.rounds.push_back(round_from_json(r));
    for (const auto& v : j.at("served")) s.served.push_back({v.at("version"), v.at("utc"), v.at("how")});
    return s;
  } catch (const json::exception& e) {
    throw Error(path + ": not a learner's state (" + e.what() + ")");
  }
}

LearnReport learn_rounds(const std::string& directory, const LearnRunOptions& o) {
  if (!o.make_evaluator) throw Error("learn_rounds: no make_evaluator given");
  const DirectoryLock lock(directory);
  LearnState s = read_learn_state(directory);
  LearnReport report;
  while (report.rounds_finished < o.rounds) {
    if (s.rounds.empty() || s.rounds.back().step == "done") {
      const PlanOutcome planned = plan_round(directory, s, o);
      if (planned == PlanOutcome::resting) {
        report.stop = LearnStop::resting;
        return report;
      }
      if (planned == PlanOutcome::budget_spent) {
        say(o, format("budget spent: %.3g of %.3g core-hours", s.spent_core_seconds / kSecondsPerHour, s.setup.budget_core_hours));
        report.stop = LearnStop::budget_spent;
        return report;
      }
    }
    if (s.rounds.back().step == "run") run_round(directory, s, o);
    if (s.rounds.back().step == "train") train_round(directory, s, o);
    if (s.rounds.back().step == "gate") gate_round(directory, s, o);
    ++report.rounds_finished;
  }
  return report;
}

void learn_rollback(const std::string& directory, const std::string& version) {
  const DirectoryLock lock(directory);
  LearnState s = read_learn_state(directory);
  const std::string kept = version_path(directory, version);
  if (!fs::exists(kept)) {
    std::string known;
    for (const auto& v : s.served) known += (known.empty() ? "" : ", ") + v.version;
    throw Error("version " + version + ": not kept by this learner (kept: " + known + ")");
  }
  publish_file(kept, s.setup.served_model);
  s.served.push_back({version, utc_timestamp(), "rolled back"});
  write_state(directory, s);
}

}  // namespace mufric
