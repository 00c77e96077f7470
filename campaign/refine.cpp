#include "campaign/refine.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <vector>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/version.hpp"
#include "surrogate/gp/active_learning.hpp"
#include "surrogate/gp/gp_training.hpp"
#include "surrogate/models/model_file.hpp"
#include "surrogate/core/sampling.hpp"
#include "surrogate/gp/stochastic_kriging.hpp"

namespace mufric {
namespace {

// The rows of a CSV with unit headers, such as the server's --log-uncertain file, in the box's
// input order (SI).
Eigen::MatrixXd csv_candidates(const std::string& path, const InputSpace& box) {
  const CsvTable table = read_csv_table(path);
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(table.rows.size()), static_cast<Eigen::Index>(box.size()));
  for (size_t j = 0; j < box.size(); ++j) {
    const std::vector<double> column = table.si_column(box[j].name);
    for (size_t i = 0; i < column.size(); ++i) rows(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = column[i];
  }
  return rows;
}

bool row_inside(const InputSpace& box, const Eigen::MatrixXd& rows, Eigen::Index i) {
  for (size_t j = 0; j < box.size(); ++j) {
    if (!box[j].contains(rows(i, static_cast<Eigen::Index>(j)))) return false;
  }
  return true;
}

// Candidate points: a Sobol' set in the box (shifted per round), plus the logged rows inside the box
// (the plan box is what the micro-model is run on; `grow` moves it toward the others first).
Eigen::MatrixXd refine_candidates(const PickOptions& o, const Eigen::MatrixXd& logged, const InputSpace& box, int round) {
  Eigen::MatrixXd c = plan_in_box(PlanDesign::sobol, o.candidate_count, box, o.seed + static_cast<unsigned long long>(round));
  std::vector<Eigen::Index> inside;
  for (Eigen::Index i = 0; i < logged.rows(); ++i) {
    if (row_inside(box, logged, i)) inside.push_back(i);
  }
  Eigen::MatrixXd all(c.rows() + static_cast<Eigen::Index>(inside.size()), c.cols());
  all.topRows(c.rows()) = c;
  for (size_t k = 0; k < inside.size(); ++k) all.row(c.rows() + static_cast<Eigen::Index>(k)) = logged.row(inside[k]);
  return all;
}

std::string box_text(const InputSpace& box) {
  std::string text;
  char cell[160];
  for (const auto& in : box) {
    std::snprintf(cell, sizeof cell, "%s%s %.6g..%.6g %s", text.empty() ? "" : ", ", in.name.c_str(), in.lo, in.hi, in.unit.c_str());
    text += cell;
  }
  return text;
}

// The database's samples that did not converge (failed or outside the model), as points: picks keep
// away from them.
Eigen::MatrixXd unconverged_points(const Dataset& db) {
  std::vector<Eigen::Index> failed_rows;
  for (Eigen::Index i = 0; i < db.size(); ++i) {
    if (!db.converged(i)) failed_rows.push_back(i);
  }
  Eigen::MatrixXd failed(static_cast<Eigen::Index>(failed_rows.size()), db.x.cols());
  for (size_t k = 0; k < failed_rows.size(); ++k) failed.row(static_cast<Eigen::Index>(k)) = db.x.row(failed_rows[k]);
  return failed;
}

// The converged samples' points, each once, with the plan row of its first sample: the candidates
// for more draws at a point already run.
struct ReplicationCandidates {
  Eigen::MatrixXd points;
  std::vector<long long> plan_rows;
};
ReplicationCandidates converged_design_points(const Dataset& db) {
  ReplicationCandidates r;
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < db.size(); ++i) {
    if (!db.converged(i)) continue;
    bool seen = false;
    for (const Eigen::Index k : rows) seen = seen || db.x.row(k) == db.x.row(i);
    if (!seen) rows.push_back(i);
  }
  r.points.resize(static_cast<Eigen::Index>(rows.size()), db.x.cols());
  for (size_t k = 0; k < rows.size(); ++k) {
    r.points.row(static_cast<Eigen::Index>(k)) = db.x.row(rows[k]);
    r.plan_rows.push_back(db.plan_index[static_cast<size_t>(rows[k])]);
  }
  return r;
}

// The draws one new sample makes: the training samples' median count.
double draws_per_sample(const TrainingSet& data) {
  const Eigen::VectorXi draws = finite_draws(data);
  std::vector<double> counts(draws.data(), draws.data() + draws.size());
  if (counts.empty()) return 1.0;
  std::nth_element(counts.begin(), counts.begin() + static_cast<std::ptrdiff_t>(counts.size() / 2), counts.end());
  return std::max(counts[counts.size() / 2], 1.0);
}

// The reference set of a round is another Sobol' shift than its candidates'.
constexpr unsigned long long kReferenceSeedOffset = 0x5eedULL;
// Fewer logged rows than this in the box say too little of where the queries are: the box instead.
constexpr long long kLeastLoggedReference = 32;

// Where the variance a pick removes is averaged: the box (a Sobol' set), or with
// reference_from_logged the logged rows inside the box — the mean squared prediction error where the
// queries are (IMSPE weighted by the query density; Binois, Huang, Gramacy & Ludkovski 2019,
// Technometrics 61:7, eq. 4 with the density the log samples) — evenly thinned to reference_count.
Eigen::MatrixXd imse_reference(const PickOptions& o, const Eigen::MatrixXd& logged, const InputSpace& box, int round) {
  if (o.reference_from_logged) {
    std::vector<Eigen::Index> inside;
    for (Eigen::Index i = 0; i < logged.rows(); ++i) {
      if (row_inside(box, logged, i)) inside.push_back(i);
    }
    if (static_cast<long long>(inside.size()) >= kLeastLoggedReference) {
      const auto n = std::min<long long>(o.reference_count, static_cast<long long>(inside.size()));
      Eigen::MatrixXd reference(n, logged.cols());
      for (long long k = 0; k < n; ++k) {
        reference.row(k) = logged.row(inside[static_cast<size_t>(k * static_cast<long long>(inside.size()) / n)]);
      }
      return reference;
    }
  }
  return plan_in_box(PlanDesign::sobol, o.reference_count, box, o.seed + kReferenceSeedOffset + static_cast<unsigned long long>(round));
}

}  // namespace

Eigen::MatrixXd logged_candidates(const std::string& path, const InputSpace& box) { return csv_candidates(path, box); }

BoxGrowth grow_plan_box(Dataset& db, const Eigen::MatrixXd& logged, double coverage, const std::string& logged_source,
                        const std::string& grown_by) {
  const InputSpace grown = grow_box(db.inputs, logged, coverage);
  BoxGrowth growth;
  growth.candidate_rows = static_cast<long long>(logged.rows());
  long long outside = 0;
  for (Eigen::Index i = 0; i < logged.rows(); ++i) outside += !row_inside(db.inputs, logged, i);
  if (same_input_space(grown, db.inputs)) return growth;
  char head[256];
  std::snprintf(head, sizeof head, "%s: grown by %s (coverage %g) toward %lld of %lld rows of ", utc_timestamp().c_str(),
                grown_by.c_str(), coverage, outside, static_cast<long long>(logged.rows()));
  growth.record = head + logged_source + " outside: " + box_text(db.inputs) + " -> " + box_text(grown);
  growth.grown = true;
  db.inputs = grown;
  db.box_history.push_back(growth.record);
  return growth;
}

GaussianProcess fit_campaign_gp(const TrainingSet& data, const GpTrainingOptions& options) {
  return suits_stochastic_kriging(data) ? train_stochastic_kriging(data, options) : train_gaussian_process(data, options);
}

std::vector<RefinePick> append_refinement_picks(Dataset& db, const GaussianProcess& gp, const TrainingSet& data,
                                                const Eigen::MatrixXd& logged, const PickOptions& o, int round, int batch) {
  const Eigen::MatrixXd sobol = refine_candidates(o, logged, db.inputs, round);
  std::vector<RefinePick> chosen;
  Eigen::MatrixXd candidates;
  if (gp.has_patch_scatter()) {
    const ReplicationCandidates replicates = converged_design_points(db);
    candidates.resize(sobol.rows() + replicates.points.rows(), sobol.cols());
    candidates << sobol, replicates.points;
    // One sample's noise at a candidate: the patch scatter there over the draws a sample makes.
    const Eigen::VectorXd noise = gp.patch_std(candidates).array().square() / draws_per_sample(data);
    const Eigen::MatrixXd reference = imse_reference(o, logged, db.inputs, round);
    for (const auto& p : pick_by_imse_reduction(gp, candidates, noise, reference, batch, unconverged_points(db))) {
      RefinePick pick;
      pick.std_at_pick = p.std_at_pick;
      pick.imse_reduction = p.imse_reduction;
      pick.plan_row = p.candidate;  // the candidate's row until it becomes a plan row below
      if (p.candidate >= sobol.rows()) pick.replicates_row = replicates.plan_rows[static_cast<size_t>(p.candidate - sobol.rows())];
      chosen.push_back(pick);
    }
  } else {
    candidates = sobol;
    for (const auto& p : pick_by_posterior_variance(gp, candidates, batch, unconverged_points(db))) {
      RefinePick pick;
      pick.std_at_pick = p.std_at_pick;
      pick.plan_row = p.candidate;
      chosen.push_back(pick);
    }
  }
  // The picks become plan rows, so the database accounts for them like any planned point; a
  // replicate is a new row at an existing row's point, with its own draws.
  const Eigen::Index first = db.plan.rows();
  db.plan.conservativeResize(first + static_cast<Eigen::Index>(chosen.size()), Eigen::NoChange);
  for (size_t k = 0; k < chosen.size(); ++k) {
    db.plan.row(first + static_cast<Eigen::Index>(k)) = candidates.row(chosen[k].plan_row);
    chosen[k].number = k + 1;
    chosen[k].plan_row = static_cast<long long>(first) + static_cast<long long>(k);
  }
  if (db.plan_design.find("active") == std::string::npos) {
    db.plan_design = db.plan_design.empty() ? "active" : db.plan_design + "+active";
  }
  return chosen;
}

namespace {
}  // namespace

long long drop_pending_plan_rows(Dataset& db, const std::string& source) {
  long long last_run = -1;
  for (const long long row : db.plan_index) last_run = std::max(last_run, row);
  const std::vector<bool> answered = answered_plan_rows(db);
  std::vector<long long> gaps;
  for (long long row = 0; row < last_run; ++row) {
    if (!answered[static_cast<size_t>(row)]) gaps.push_back(row);
  }
  if (!gaps.empty()) {
    std::string list;
    for (size_t k = 0; k < std::min<size_t>(gaps.size(), 8); ++k) list += (k ? ", " : "") + std::to_string(gaps[k]);
    if (gaps.size() > 8) list += ", ...";
    throw Error(source + ": plan rows " + list + " have not run but lie before row " + std::to_string(last_run) +
                ", which has; run them first (mufric dataset run) so that only the plan's tail is left out");
  }
  const long long kept = last_run + 1, dropped = db.plan.rows() - kept;
  if (dropped <= 0) return 0;
  db.plan.conservativeResize(kept, Eigen::NoChange);
  db.plan_design = (db.plan_design.empty() ? std::string("plan") : db.plan_design) + " prefix of " + std::to_string(kept);
  return dropped;
}

RefineReport refine_dataset(const RefineOptions& o) {
  if (!o.make_evaluator) throw Error("refine_dataset: no make_evaluator given");
  Dataset db = read_dataset_isolated(o.db);
  if (db.plan.rows() == 0 || db.plan_index.size() != static_cast<size_t>(db.size())) {
    throw Error(o.db + ": not a micro-model database (no plan rows); start with mufric dataset plan and run");
  }
  if (o.drop_pending) {
    const long long dropped = drop_pending_plan_rows(db, o.db);
    if (dropped > 0) write_dataset(o.db, db);
    if (o.on_drop) o.on_drop(dropped);
  }
  const Eigen::MatrixXd logged = o.candidates_csv.empty() ? Eigen::MatrixXd(0, static_cast<Eigen::Index>(db.inputs.size()))
                                                            : csv_candidates(o.candidates_csv, db.inputs);
  if (o.grow) {
    const BoxGrowth growth = grow_plan_box(db, logged, o.grow_coverage, o.candidates_csv, "dataset refine --grow-box");
    if (growth.grown) write_dataset(o.db, db);
    if (o.on_box) o.on_box(growth);
  }
  const SampleEvaluator evaluate = o.make_evaluator(db);
  std::optional<TrainingSet> test;
  if (!o.test.empty()) test = training_set(read_dataset_isolated(o.test), o.test);
  GpTrainingOptions training;
  training.restarts = o.restarts;
  training.seed = o.seed;
  const PickOptions picking{o.candidate_count, o.reference_count, o.seed};
  RefineReport report;
  for (int round = 1;; ++round) {
    const TrainingSet data = training_set(db, o.db);
    const GaussianProcess gp = fit_campaign_gp(data, training);
    if (o.on_round) {
      const auto& sum = gp.state().summary;
      RefineRound r;
      r.round = round;
      r.training_samples = static_cast<long long>(data.x.rows());
      r.loo_mean_relative_error = sum.loo_mean_relative_error;
      r.loo_max_relative_error = sum.loo_max_relative_error;
      std::optional<AccuracyReport> held_out;
      if (test) {
        held_out = held_out_accuracy(gp, *test, 0.95);
        r.held_out = &*held_out;
        r.held_out_source = test->source_path;
      }
      o.on_round(r);
    }
    if (!o.model_out.empty()) save_model(o.model_out, gp);
    if (report.spent >= o.budget) break;
    const int batch = static_cast<int>(std::min<long long>(o.batch, o.budget - report.spent));
    for (const RefinePick& pick : append_refinement_picks(db, gp, data, logged, picking, round, batch)) {
      if (o.on_pick) o.on_pick(pick);
    }
    write_dataset(o.db, db);
    GenerationOptions options;
    options.jobs = o.jobs;
    if (o.on_sample) {
      options.on_sample = [&](const GenerationProgress& p) { o.on_sample(p, db.inputs, db.plan.row(p.plan_row).transpose()); };
    }
    const GenerationReport r = generate_dataset(db, o.db, evaluate, options);
    report.spent += r.ran;
    db = read_dataset_isolated(o.db);
    if (r.ran == 0) break;  // nothing new could be run
  }
  return report;
}

}  // namespace mufric
