#include "campaign/learning.hpp"

#include <fcntl.h>
#include <sys/stat.h>
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
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "campaign/campaign_summary.hpp"
#include "campaign/refine.hpp"
#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/version.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric {

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

// ---- the state file: DIR/learn.json (its types' (de)serialisers are at the namespace's top) ----

void write_state(const std::string& dir, const LearnState& s) {
  const json j = {{"format", "mufric learn state 1"},
                  {"setup", s.setup},
                  {"log_offset", s.log_offset},
                  {"log_file_id", s.log_file_id},
                  {"queries_seen", s.queries_seen},
                  {"spent_core_seconds", s.spent_core_seconds},
                  {"rounds", s.rounds},
                  {"served", s.served}};
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
// the next round), as a CSV with the file's header; the new offset and the file it is in. The server
// renames a full log to NAME.csv.1 and begins a new one (common/uncertain_log.hpp): when the file read
// last time (`file_id`, its inode; 0: not known) is now the renamed one, its rest is read first, then
// the new file from its start. A log shorter than the offset in the same file was started afresh by
// an operator: it is read from its start.
struct NewLogRows {
  std::string csv;  // header + the new lines ("" when the log does not exist)
  long long rows = 0;
  long long end_offset = 0;
  long long file_id = 0;
};

long long file_id_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<long long>(st.st_ino) : 0;
}

// The whole lines of `text` after `offset` (from the line after the header when offset is inside it or
// past the end), and the offset after them.
std::pair<std::string, long long> lines_after(const std::string& text, long long offset) {
  const auto header_end = text.find('\n');
  if (header_end == std::string::npos) return {"", offset};
  const long long size = static_cast<long long>(text.size());
  const long long start = offset > size || offset <= static_cast<long long>(header_end) ? static_cast<long long>(header_end) + 1 : offset;
  const long long end = static_cast<long long>(text.rfind('\n')) + 1;
  if (end <= start) return {"", start};
  return {text.substr(static_cast<size_t>(start), static_cast<size_t>(end - start)), end};
}

NewLogRows read_new_log_rows(const std::string& path, long long offset, long long file_id) {
  NewLogRows out;
  out.end_offset = offset;
  out.file_id = file_id;
  std::string rows, header;
  const long long current_id = file_id_of(path);
  if (file_id != 0 && current_id != file_id) {  // renamed since the last look
    const std::string rotated = rotated_log_path(path);
    const auto old_text = file_id_of(rotated) == file_id ? read_whole_file(rotated) : std::nullopt;
    if (old_text) {
      rows = lines_after(*old_text, offset).first;
      header = old_text->substr(0, old_text->find('\n') + 1);
    }
    offset = 0;  // the new file from its start
  }
  const auto text = read_whole_file(path);
  if (text && text->find('\n') != std::string::npos) {
    auto [more, end] = lines_after(*text, offset);
    rows += more;
    header = text->substr(0, text->find('\n') + 1);
    out.end_offset = end;
    out.file_id = current_id;
  }
  if (header.empty()) return out;
  out.csv = header + rows;
  out.rows = static_cast<long long>(std::count(rows.begin(), rows.end(), '\n'));
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

// The served model's policies (extrapolation, μ range) carry over; its grids are built to `fast`
// (none without: a calibrated model's emulator serves through the calibrated model's own grid).
GaussianProcess train_candidate(const Dataset& db, const std::string& db_path, const FrictionModel& served,
                                const LearnSetup& setup, const FastEvaluatorOptions* fast) {
  TrainingSet data = training_set(db, db_path);
  data.description = campaign_summary(db);
  GpTrainingOptions training;
  training.restarts = setup.restarts;
  training.seed = setup.seed;
  GaussianProcess gp = fit_campaign_gp(data, training);
  gp.set_default_extrapolation(served.default_extrapolation());
  gp.set_mu_range(served.mu_min(), served.mu_max());
  if (fast != nullptr) attach_fast_evaluators(gp, *fast, build_kept_fast_evaluator);
  return gp;
}

const CalibratedModel* as_calibrated(const FrictionModel& model) { return dynamic_cast<const CalibratedModel*>(&model); }

// What the learner serves: a campaign's GP, or a calibrated model whose emulator is one.
std::unique_ptr<FrictionModel> load_served(const std::string& path, const std::string& role) {
  std::unique_ptr<FrictionModel> model = load_model_isolated(path);
  if (dynamic_cast<const GaussianProcess*>(model.get()) == nullptr && as_calibrated(*model) == nullptr) {
    throw Error(path + ": the " + role + " is a " + std::string(model->kind()) +
                " model; the learner retrains a campaign's GP, or recalibrates a calibrated model with the retrained GP");
  }
  return model;
}

// The campaign's GP a served model stands on: itself, or a calibrated model's emulator.
const GaussianProcess& campaign_gp_of(const FrictionModel& model) {
  if (const CalibratedModel* calibrated = as_calibrated(model)) return calibrated->emulator();
  return dynamic_cast<const GaussianProcess&>(model);
}

// The logged rows, a calibrated model's served conditions, as rows of its emulator's inputs: each
// at the coefficients of one posterior sample (the kept samples spread over the rows in order), held
// inputs at their value. There the posterior predictive evaluates the emulator, so that is where
// runs make the calibrated model sure.
Eigen::MatrixXd at_posterior_samples(const CalibratedModel& model, const Eigen::MatrixXd& conditions) {
  const CalibrationProblem& problem = model.problem();
  const Eigen::MatrixXd& samples = model.samples();
  const Eigen::Index n = conditions.rows(), kept = samples.rows();
  Eigen::MatrixXd rows(n, static_cast<Eigen::Index>(model.emulator().inputs().size()));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::VectorXd theta = samples.row((i * kept) / n).head(problem.parameter_count()).transpose();
    rows.row(i) = problem.emulator_points(conditions.row(i), theta).row(0);
  }
  return rows;
}

// A recalibrated model's grid, when the served one had one (a grid of the posterior predictive costs
// minutes; a model served exact stays exact).
void attach_calibrated_grid(CalibratedModel& model, const CalibratedModel& served, FastEvaluatorOptions options) {
  if (served.fast_evaluator() == nullptr) return;
  if (!(options.max_work > 0.0)) options.max_work = kLeastFastEvaluatorWork;
  model.attach_fast_evaluator(
      build_kept_fast_evaluator(GridSource{model, model.unit_length_scales(), model.exact_point_work()}, options, "calibrated model"));
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
  if (!fs::exists(kept)) copy_file_atomically(file, kept);
  if (!s.served.empty() && s.served.back().version == version) return;  // a resumed step, already recorded
  s.served.push_back({version, utc_timestamp(), how});
}

// Plan rows of the database no sample answers, as [first, end): a kill after the picks were written
// and before the state recorded them leaves them there, and they are the round's.
std::pair<long long, long long> pending_rows(const Dataset& db) {
  const std::vector<bool> answered = answered_plan_rows(db);
  long long first = db.plan.rows();
  for (long long row = 0; row < db.plan.rows(); ++row) {
    if (!answered[static_cast<size_t>(row)]) {
      first = row;
      break;
    }
  }
  return {first, db.plan.rows()};
}

// The micro-model's own time (micro_wall_seconds) of the samples answering plan rows [first, end),
// and how many recorded it: what a round's runs cost when another engine ran them, and the mean
// cost a budget is planned with.
struct RecordedSeconds {
  double seconds = 0.0;
  long long samples = 0;
};
RecordedSeconds recorded_micro_seconds(const Dataset& db, long long first, long long end) {
  RecordedSeconds r;
  const auto it = db.diagnostics.find("micro_wall_seconds");
  if (it == db.diagnostics.end()) return r;
  for (Eigen::Index i = 0; i < db.size(); ++i) {
    const long long row = db.plan_index[static_cast<size_t>(i)];
    if (row >= first && row < end && std::isfinite(it->second(i))) {
      r.seconds += it->second(i);
      ++r.samples;
    }
  }
  return r;
}

// The mean core-seconds of a sample so far (the database's record, else the learner's own count),
// for how many runs the budget still allows; 0 when nothing is known.
double mean_sample_core_seconds(const Dataset& db, const LearnState& s, int threads_per_job) {
  const RecordedSeconds recorded = recorded_micro_seconds(db, -1, db.plan.rows());  // −1: a sample of no plan row
  if (recorded.samples > 0) return threads_per_job * recorded.seconds / static_cast<double>(recorded.samples);
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
  const NewLogRows logged = read_new_log_rows(setup.log, s.log_offset, s.log_file_id);
  const long long queries = logged_query_count(setup.log);
  const long long new_queries = queries < 0 ? -1 : (s.queries_seen >= 0 && queries >= s.queries_seen ? queries - s.queries_seen : queries);
  round.logged_rows = logged.rows;
  // At most 1: the counts restart with a reloaded model's box while its log goes on.
  round.uncertain_share =
      new_queries > 0 ? std::min(1.0, static_cast<double>(logged.rows) / static_cast<double>(new_queries)) : -1.0;
  s.log_offset = logged.end_offset;
  s.log_file_id = logged.file_id;
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
  const std::unique_ptr<FrictionModel> served = load_served(setup.served_model, "served model");
  const CalibratedModel* calibrated = as_calibrated(*served);
  const Eigen::MatrixXd rows = calibrated != nullptr ? at_posterior_samples(*calibrated, logged_candidates(rows_path, calibrated->inputs()))
                                                     : logged_candidates(rows_path, db.inputs);
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
        o.threads_per_job *
        recorded_micro_seconds(read_dataset_isolated(s.setup.db), round.first_plan_row, round.end_plan_row).seconds;
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
  const std::unique_ptr<FrictionModel> served = load_served(s.setup.served_model, "served model");
  const CalibratedModel* calibrated = as_calibrated(*served);
  const Dataset db = read_dataset_isolated(s.setup.db);
  say(o, format("round %d: training on %lld samples", round.number, static_cast<long long>(db.size())));
  GaussianProcess emulator = train_candidate(db, s.setup.db, campaign_gp_of(*served), s.setup, calibrated ? nullptr : &o.fast);
  round.candidate = (fs::path(dir) / "candidates" / ("round-" + std::to_string(round.number) + ".h5")).string();
  if (calibrated == nullptr) {
    save_model(round.candidate, emulator);
  } else {
    say(o, format("round %d: recalibrating on the served model's %lld measurements", round.number,
                  static_cast<long long>(calibrated->problem().data().rows())));
    const Recalibration r = recalibrate(*calibrated, std::make_shared<const GaussianProcess>(std::move(emulator)), o.recalibration_max_steps);
    if (!r.result.convergence_failure.empty()) {  // no candidate: kept aside at once, with the reason
      round.candidate.clear();
      round.gate = GateDecision{};
      round.gate.reason = "the recalibration's chains are not usable: " + r.result.convergence_failure;
      round.step = "done";
      round.finished_utc = utc_timestamp();
      write_state(dir, s);
      say(o, format("round %d: kept aside: %s", round.number, round.gate.reason.c_str()));
      return;
    }
    CalibratedModel model = calibrated_model(r.setup, r.result);
    attach_calibrated_grid(model, *calibrated, o.fast);
    save_model(round.candidate, model);
  }
  round.version = file_version(round.candidate);
  round.step = "gate";
  write_state(dir, s);
}

// The samples of a round whose values the gate refused, marked failed with the reason (μ kept, for
// whoever looks into it): later rounds train without them and do not run their plan rows again.
// Idempotent (a resumed gate step finds them marked); returns how many are marked.
long long quarantine_round(const std::string& db_path, const LearnRound& round) {
  Dataset db = read_dataset_isolated(db_path);
  const std::string reason = "quarantined by mufric learn: round " + std::to_string(round.number) +
                             "'s gate refused its values (" + round.gate.reason.substr(0, round.gate.reason.find(':')) + ")";
  long long marked = 0, newly = 0;
  for (Eigen::Index i = 0; i < db.size(); ++i) {
    const long long row = db.plan_index[static_cast<size_t>(i)];
    if (row < round.first_plan_row || row >= round.end_plan_row) continue;
    std::string& why = db.failure_reason[static_cast<size_t>(i)];
    if (why == reason) {
      ++marked;
    } else if (!db.failed(i)) {
      db.status[static_cast<size_t>(i)] = static_cast<long long>(SampleStatus::failed);
      why = reason;
      ++marked;
      ++newly;
    }
  }
  if (newly > 0) write_dataset(db_path, db);
  return marked;
}

// Step 5: gated, and published or kept aside.
void gate_round(const std::string& dir, LearnState& s, const LearnRunOptions& o) {
  LearnRound& round = s.rounds.back();
  // The decision is recorded before it is carried out and never made twice: a learner stopped after
  // publishing and before recording it would otherwise gate the candidate against itself (now the
  // served file) and keep it aside as adding no point.
  if (round.gate.reason.empty()) {
    const std::unique_ptr<FrictionModel> served = load_served(s.setup.served_model, "served model");
    const std::unique_ptr<FrictionModel> candidate = load_served(round.candidate, "candidate");
    say(o, format("round %d: gating %s against the served model", round.number, round.version.c_str()));
    const CalibratedModel *served_calibrated = as_calibrated(*served), *candidate_calibrated = as_calibrated(*candidate);
    if ((served_calibrated == nullptr) != (candidate_calibrated == nullptr)) {  // the served file was replaced meanwhile
      round.gate = GateDecision{};
      round.gate.reason = "the candidate is a " + std::string(candidate->kind()) + " model and the served one now a " +
                          std::string(served->kind()) + " model";
    } else if (served_calibrated != nullptr) {
      round.gate = gate_calibrated_candidate(*served_calibrated, *candidate_calibrated, o.fast);
    } else {
      round.gate = gate_candidate(campaign_gp_of(*served), campaign_gp_of(*candidate), o.fast);
    }
    write_state(dir, s);
  } else {
    say(o, format("round %d: carrying out the gate's decision on %s, made before the learner stopped", round.number,
                  round.version.c_str()));
  }
  if (round.gate.publish) {
    keep_version(dir, s, round.candidate, "published by round " + std::to_string(round.number));
    // One rename: the server's reload sees the old file or the new one (the temporary's name does
    // not end in .h5, so the registry never opens it).
    copy_file_atomically(round.candidate, s.setup.served_model);
  } else if (round.gate.values_refused) {
    round.quarantined = quarantine_round(s.setup.db, round);
    say(o, format("round %d: its %lld samples quarantined in %s (marked failed with the reason; later rounds train without them)",
                  round.number, round.quarantined, s.setup.db.c_str()));
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

namespace {

// A gate's decision and its verdict's first words; the figures it rests on (gate_figures) follow
// unless the verdict came before any (another input space, another database).
struct Judged {
  GateDecision decision;
  std::string verdict;
  bool figures_follow = false;
};

std::string gate_figures(const GateDecision& g) {
  std::string figures = format("leave-one-out RMSE on the served version's %lld points %.3g (served %.3g, at most %.3g); "
                               "%lld of %lld new points inside their 95 %% interval",
                               g.old_points, g.candidate_loo_rmse, g.served_loo_rmse, g.allowed_loo_rmse, g.new_covered, g.new_points);
  if (g.measurements > 0) {
    figures += format("; recalibrated: %lld of %lld measurements inside the 95 %% predictive interval", g.measurements_covered,
                      g.measurements);
  }
  return figures;
}

// gate_candidate's checks.
Judged judge_candidate(const GaussianProcess& served, const GaussianProcess& candidate, const FastEvaluatorOptions& tolerances) {
  Judged judged;
  GateDecision& g = judged.decision;
  std::string& why = judged.verdict;
  // The box may have grown; the inputs must still be the same names in the same order.
  if (input_names(served.inputs()) != input_names(candidate.inputs())) {
    why = "the candidate's inputs are not the served model's";
    return judged;
  }
  const auto& old_state = served.state();
  const auto& new_state = candidate.state();
  const LeaveOneOut old_loo = leave_one_out_points(old_state), new_loo = leave_one_out_points(new_state);
  if (old_loo.error.size() == 0 || new_loo.error.size() == 0) {
    why = "leave-one-out could not be computed (a factor could not be inverted)";
    return judged;
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
    why = format("the candidate was not trained on all the served version's points (%lld of %lld found): another database",
                 g.old_points, static_cast<long long>(old_state.x_train.rows()));
    return judged;
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
  judged.figures_follow = true;
  if (g.new_points == 0) {
    why = "the round added no converged point; ";
  } else if (g.candidate_loo_rmse > g.allowed_loo_rmse) {
    why = "worse on what the served version knew: ";
    g.values_refused = true;
  } else if (binomial_lower_tail(g.new_covered, g.new_points, kCoverageLevel) < kGateCoverageSignificance) {
    why = format("its interval misses its new points more often than a 95 %% interval may (binomial p < %g): ", kGateCoverageSignificance);
    g.values_refused = true;
  } else if (!g.grid_certified) {
    why = "its fast evaluator does not meet the tolerances the served one met; ";
  } else {
    g.publish = true;
    why = "no worse: ";
  }
  return judged;
}

// Of a calibrated model's measurements, those inside its 95 % posterior predictive interval widened
// by the measurement's own SD (the predictive is of the true μ; a measurement scatters about it).
long long measurements_covered(const CalibratedModel& model) {
  const Measurements& data = model.problem().data();
  EvaluationRequest exact;
  exact.std = true;
  exact.mu_tolerance = 0.0;  // the exact predictive, not a grid of it
  const Evaluation e = model.evaluate(data.conditions, exact);
  long long covered = 0;
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    covered += std::abs(data.mu(i) - e.mu(i)) <= kZ95 * std::hypot(e.std(i), data.mu_sd(i));
  }
  return covered;
}

}  // namespace

GateDecision gate_candidate(const GaussianProcess& served, const GaussianProcess& candidate, const FastEvaluatorOptions& tolerances) {
  Judged judged = judge_candidate(served, candidate, tolerances);
  judged.decision.reason = judged.verdict + (judged.figures_follow ? gate_figures(judged.decision) : "");
  return judged.decision;
}

GateDecision gate_calibrated_candidate(const CalibratedModel& served, const CalibratedModel& candidate,
                                       const FastEvaluatorOptions& tolerances) {
  Judged judged = judge_candidate(served.emulator(), candidate.emulator(), tolerances);  // emulators: no grid in the file
  GateDecision& g = judged.decision;
  g.measurements = candidate.problem().data().rows();
  g.measurements_covered = measurements_covered(candidate);
  const long long served_covered = measurements_covered(served);
  const FastEvaluator* served_grid = served.fast_evaluator();
  const FastEvaluator* candidate_grid = candidate.fast_evaluator();
  g.grid_certified = served_grid == nullptr || !served_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance) ||
                     (candidate_grid != nullptr && candidate_grid->meets(tolerances.mu_tolerance, tolerances.std_relative_tolerance));
  // A data set with a bias of its own may leave the served version's coverage short of 95 %: the
  // candidate is refused only for a shortfall it adds.
  if (g.publish && g.measurements_covered < served_covered &&
      binomial_lower_tail(g.measurements_covered, g.measurements, kCoverageLevel) < kGateCoverageSignificance) {
    g.publish = false;
    g.values_refused = true;
    judged.verdict = format("its posterior predictive misses the measurements more often than a 95 %% interval may (binomial p < %g) "
                            "and more often than the served version's: ", kGateCoverageSignificance);
  } else if (g.publish && !g.grid_certified) {
    g.publish = false;
    judged.verdict = "its fast evaluator does not meet the tolerances the served one met; ";
  }
  g.reason = judged.verdict + (judged.figures_follow ? gate_figures(g) + format(" (served %lld)", served_covered) : "");
  return g;
}

void learn_init(const std::string& directory, const LearnSetup& setup) {
  if (fs::exists(state_path(directory))) throw Error(directory + ": already holds a learner (" + state_path(directory) + ")");
  if (setup.round_samples < 1) throw Error("round samples: must be at least 1");
  if (!(setup.budget_core_hours > 0.0)) throw Error("budget core-hours: must be positive");
  if (!(setup.rest_below >= 0.0 && setup.rest_below < 1.0)) throw Error("rest below: must lie in [0, 1)");
  const Dataset db = read_dataset_isolated(setup.db);
  if (db.plan.rows() == 0) throw Error(setup.db + ": not a campaign database (no plan rows); start with mufric dataset plan and run");
  if (fs::path(setup.served_model).extension() != ".h5") throw Error(setup.served_model + ": a served model's file name ends in .h5");
  const std::unique_ptr<FrictionModel> served = load_served(setup.served_model, "served model");
  if (const CalibratedModel* calibrated = as_calibrated(*served)) {
    if (!calibrated->record().priors_kept) {
      throw Error(setup.served_model + ": a calibrated model written before calibrated files kept their priors cannot be "
                  "recalibrated by the learner: calibrate it again with mufric calibrate");
    }
    if (input_names(calibrated->emulator().inputs()) != input_names(db.inputs)) {
      throw Error(setup.served_model + ": the calibrated model's emulator is not a GP of " + setup.db + " (its inputs differ)");
    }
  }
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
  copy_file_atomically(kept, s.setup.served_model);
  s.served.push_back({version, utc_timestamp(), "rolled back"});
  write_state(directory, s);
}

}  // namespace mufric
