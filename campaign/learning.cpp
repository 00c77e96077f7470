#include "campaign/learning.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "campaign/campaign_summary.hpp"
#include "campaign/learning_log.hpp"
#include "campaign/refine.hpp"
#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/version.hpp"
#include "common/wording.hpp"
#include "surrogate/calibration/calibration_run.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"

namespace mufric {


namespace {

namespace fs = std::filesystem;

constexpr double kSecondsPerHour = 3600.0;

std::string version_path(const std::string& dir, const std::string& version) {
  return (fs::path(dir) / "versions" / (version + ".h5")).string();
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
    say(o, text_printf("round %d: the database holds %lld planned rows not yet run; they are this round's", round.number, end - first));
    round.first_plan_row = first;
    round.end_plan_row = end;
    round.step = LearnStep::run;
    s.rounds.push_back(round);
    write_learn_state(dir, s);
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
               ? text_printf("resting: %lld of %lld queries logged as uncertain or outside since the last look (%.2g %%, below %.2g %%)",
                        logged.rows, new_queries, 100.0 * round.uncertain_share, 100.0 * setup.rest_below)
               : text_printf("resting: no query logged as uncertain or outside since the last look (%s)", setup.log.c_str()));
    write_learn_state(dir, s);
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
  round.step = LearnStep::run;
  s.rounds.push_back(round);
  write_learn_state(dir, s);
  say(o, text_printf("round %d: %lld logged rows (%s of the queries); planned %zu runs, plan rows %lld-%lld", round.number, logged.rows,
                round.uncertain_share >= 0.0 ? text_printf("%.2g %%", 100.0 * round.uncertain_share).c_str() : "share unknown",
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
    say(o, text_printf("round %d: plan rows %lld-%lld handed to the engine (%s)", round.number, round.first_plan_row,
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
      write_learn_state(dir, s);
      say(o, text_printf("round %d: sample %lld/%lld (plan row %lld) %s in %.1f s; spent %.3g of %.3g core-hours", round.number,
                    p.finished, p.to_run, p.plan_row,
                    p.outcome && p.outcome->converged ? text_printf("mu %.5f", p.outcome->mu).c_str() : "failed", p.sample_seconds,
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
  round.step = LearnStep::train;
  write_learn_state(dir, s);
}

// Step 4: the candidate trained and saved.
void train_round(const std::string& dir, LearnState& s, const LearnRunOptions& o) {
  LearnRound& round = s.rounds.back();
  const std::unique_ptr<FrictionModel> served = load_served(s.setup.served_model, "served model");
  const CalibratedModel* calibrated = as_calibrated(*served);
  const Dataset db = read_dataset_isolated(s.setup.db);
  say(o, text_printf("round %d: training on %lld samples", round.number, static_cast<long long>(db.size())));
  GaussianProcess emulator = train_candidate(db, s.setup.db, campaign_gp_of(*served), s.setup, calibrated ? nullptr : &o.fast);
  round.candidate = (fs::path(dir) / "candidates" / ("round-" + std::to_string(round.number) + ".h5")).string();
  if (calibrated == nullptr) {
    save_model(round.candidate, emulator);
  } else {
    say(o, text_printf("round %d: recalibrating on the served model's %lld measurements", round.number,
                  static_cast<long long>(calibrated->problem().data().rows())));
    // The sampler's words as the round's: its summary and warnings line by line, its progress by tenths.
    const std::string prefix = text_printf("round %d: ", round.number);
    const CalibrationSay report = [&o, &prefix](const std::string& text) {
      std::istringstream lines(text);
      for (std::string line; std::getline(lines, line);) say(o, prefix + line);
    };
    const CalibrationSay progress = [&o, &prefix](const std::string& line) { say(o, prefix + "recalibration " + line); };
    const CalibrationRun r = recalibrate(*calibrated, std::make_shared<const GaussianProcess>(std::move(emulator)),
                                         o.recalibration_max_steps, report, progress);
    if (!r.result.convergence_failure.empty()) {  // no candidate: kept aside at once, with the reason
      round.candidate.clear();
      round.gate = GateDecision{};
      round.gate.reason = "the recalibration's chains are not usable: " + r.result.convergence_failure;
      round.step = LearnStep::done;
      round.finished_utc = utc_timestamp();
      write_learn_state(dir, s);
      say(o, text_printf("round %d: kept aside: %s", round.number, round.gate.reason.c_str()));
      return;
    }
    CalibratedModel model = calibrated_model(r.setup, r.result);
    attach_calibrated_grid(model, *calibrated, o.fast);
    save_model(round.candidate, model);
  }
  round.version = file_version(round.candidate);
  round.step = LearnStep::gate;
  write_learn_state(dir, s);
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
    say(o, text_printf("round %d: gating %s against the served model", round.number, round.version.c_str()));
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
    write_learn_state(dir, s);
  } else {
    say(o, text_printf("round %d: carrying out the gate's decision on %s, made before the learner stopped", round.number,
                  round.version.c_str()));
  }
  if (round.gate.publish) {
    keep_version(dir, s, round.candidate, "published by round " + std::to_string(round.number));
    // One rename: the server's reload sees the old file or the new one (the temporary's name does
    // not end in .h5, so the registry never opens it).
    copy_file_atomically(round.candidate, s.setup.served_model);
  } else if (round.gate.values_refused) {
    round.quarantined = quarantine_round(s.setup.db, round);
    say(o, text_printf("round %d: its %lld samples quarantined in %s (marked failed with the reason; later rounds train without them)",
                  round.number, round.quarantined, s.setup.db.c_str()));
  }
  round.step = LearnStep::done;
  round.finished_utc = utc_timestamp();
  write_learn_state(dir, s);
  say(o, text_printf("round %d: %s %s: %s", round.number, round.gate.publish ? "published" : "kept aside", round.version.c_str(),
                round.gate.reason.c_str()));
}

}  // namespace

void learn_init(const std::string& directory, const LearnSetup& setup) {
  if (fs::exists(learn_state_path(directory))) throw Error(directory + ": already holds a learner (" + learn_state_path(directory) + ")");
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
  write_learn_state(directory, s);
}


LearnReport learn_rounds(const std::string& directory, const LearnRunOptions& o) {
  if (!o.make_evaluator) throw Error("learn_rounds: no make_evaluator given");
  const LearnerLock lock(directory);
  LearnState s = read_learn_state(directory);
  LearnReport report;
  while (report.rounds_finished < o.rounds) {
    if (s.rounds.empty() || s.rounds.back().step == LearnStep::done) {
      const PlanOutcome planned = plan_round(directory, s, o);
      if (planned == PlanOutcome::resting) {
        report.stop = LearnStop::resting;
        return report;
      }
      if (planned == PlanOutcome::budget_spent) {
        say(o, text_printf("budget spent: %.3g of %.3g core-hours", s.spent_core_seconds / kSecondsPerHour, s.setup.budget_core_hours));
        report.stop = LearnStop::budget_spent;
        return report;
      }
    }
    if (s.rounds.back().step == LearnStep::run) run_round(directory, s, o);
    if (s.rounds.back().step == LearnStep::train) train_round(directory, s, o);
    if (s.rounds.back().step == LearnStep::gate) gate_round(directory, s, o);
    ++report.rounds_finished;
  }
  return report;
}

void learn_rollback(const std::string& directory, const std::string& version) {
  const LearnerLock lock(directory);
  LearnState s = read_learn_state(directory);
  const std::string kept = version_path(directory, version);
  if (!fs::exists(kept)) {
    std::string known;
    for (const auto& v : s.served) known += (known.empty() ? "" : ", ") + v.version;
    throw Error("version " + version + ": not kept by this learner (kept: " + known + ")");
  }
  copy_file_atomically(kept, s.setup.served_model);
  s.served.push_back({version, utc_timestamp(), "rolled back"});
  write_learn_state(directory, s);
}

}  // namespace mufric
