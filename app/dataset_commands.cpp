// `mufric dataset plan / run / refine / status / merge`: the micro-model as a dataset factory. The
// work (generation, merge, refine) is campaign/'s; here flags are parsed, the micro-model is wired in
// as the sample evaluator, and progress is printed.
#include <unistd.h>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/input_flags.hpp"
#include "app/sample_evaluators.hpp"
#include "campaign/dataset_generation.hpp"
#include "campaign/campaign_summary.hpp"
#include "campaign/refine.hpp"
#include "common/environment.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
#include "common/version.hpp"
#include "common/wording.hpp"
#include "micro/run/dataset_sample.hpp"
#include "micro/run/measurement.hpp"
#include "surrogate/core/accuracy.hpp"
#include "surrogate/calibration/measurements.hpp"
#include "surrogate/core/sampling.hpp"

namespace mufric::app {
namespace {

// "300MPa:1300MPa" → {lo, hi} in SI.
std::pair<double, double> parse_range(const std::string& text, QuantityKind kind, const std::string& flag) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw Error(flag + " '" + text + "': give lo:hi with units, e.g. 300MPa:1300MPa");
  const double lo = parse_quantity(text.substr(0, colon), kind, flag);
  const double hi = parse_quantity(text.substr(colon + 1), kind, flag);
  for (const double end : {lo, hi}) {
    const std::string why = physical_range_violation(end, kind);
    if (!why.empty()) throw Error(flag + " '" + text + "': " + why);
  }
  if (!(lo < hi)) throw Error(flag + " '" + text + "': the lower end must lie below the upper end");
  return {lo, hi};
}

// The inputs a micro-model scene can set besides p, v, T: the interface law's coefficients.
std::vector<const scene::SettableInput*> law_coefficient_inputs() {
  std::vector<const scene::SettableInput*> coefficients;
  const InputSpace box = default_friction_box();
  for (const scene::SettableInput& input : scene::settable_inputs()) {
    const bool in_box = std::any_of(box.begin(), box.end(), [&](const InputSpec& s) { return s.name == input.input; });
    if (!in_box) coefficients.push_back(&input);
  }
  return coefficients;
}

void print_box(const InputSpace& box) {
  for (const auto& input : box) {
    std::printf("  %-17s %s .. %s\n", input.name.c_str(), format_human(input.lo, input.kind()).c_str(),
                format_human(input.hi, input.kind()).c_str());
  }
}

struct PlanOptions {
  std::string out, design = "sobol", scene_path, box_from;
  double box_margin = 0.25;
  std::map<std::string, std::string> ranges;  // flag (--p, --v, --T) → range text
  std::vector<std::string> overrides;
  long long samples = 64;
  unsigned long long seed = 0;
  bool common_tools = false;
};

void plan_command(const PlanOptions& o) {
  InputSpace box = default_friction_box();
  if (!o.box_from.empty()) {
    // The measured rows' conditions set the box (a condition they do not give keeps seed 000's range);
    // an explicit --p, --v or --T still wins.
    const InputSpace measured = box_for_measurements(read_measurements(o.box_from), o.box_margin);
    for (auto& input : box)
      for (const InputSpec& m : measured)
        if (m.name == input.name) std::tie(input.lo, input.hi) = std::pair{m.lo, m.hi};
    std::printf("box from %s (each condition over its rows, +-%g SD where uncertain, widened by %g of its width on each side, "
                "pressure and velocity in log):\n",
                o.box_from.c_str(), kBoxSds, o.box_margin);
  }
  for (auto& input : box) {
    const std::string flag(flag_of(input.name));
    const auto text = o.ranges.find(flag);
    if (text != o.ranges.end() && !text->second.empty()) std::tie(input.lo, input.hi) = parse_range(text->second, input.kind(), flag);
  }
  // A law coefficient given a range becomes an input of the plan, after p, v, T (a calibration's θ).
  for (const scene::SettableInput* coefficient : law_coefficient_inputs()) {
    const auto text = o.ranges.find(std::string(flag_of(coefficient->input)));
    if (text == o.ranges.end() || text->second.empty()) continue;
    InputSpec input{std::string(coefficient->input), std::string(si_unit(coefficient->kind)), 0.0, 0.0};
    std::tie(input.lo, input.hi) = parse_range(text->second, coefficient->kind, text->first);
    box.push_back(input);
  }
  const scene::Scene sc = scene::load_scene(o.scene_path, o.overrides);
  run::micro_evaluator(sc, box, 1);  // refuses a scene the dataset cannot drive, before anything is written
  const PlanDesign design = parse_plan_design(o.design);
  Dataset spec;
  spec.inputs = box;
  spec.plan = plan_in_box(design, o.samples, box, o.seed);
  spec.plan_design = plan_design_name(design);
  spec.plan_seed = static_cast<long long>(o.seed);
  spec.draws = o.common_tools ? DrawDesign::common : DrawDesign::independent;
  spec.scene_json = sc.effective.dump(2);
  // What a reader of `dataset status` needs first: which physics, and whether the named scene was changed.
  const std::string scene_label = sc.source + (o.overrides.empty() ? "" : " with " + std::to_string(o.overrides.size()) + " --set") +
                                  ", physics " + scene::choice_name(sc.physics);
  spec.source = "micro-model plan (" + scene_label + ")";
  const Dataset plan = empty_dataset(spec);
  write_dataset(o.out, plan);
  std::printf("wrote %s: %s, %s design (seed %llu), %s, scene %s (sha256 %s)\n", o.out.c_str(), count_of(o.samples, "point", "points").c_str(),
              plan.plan_design.c_str(), o.seed,
              o.common_tools ? "every row on the scene's own tool and chip surfaces (common draws)"
                             : "every row its own tool and chip surfaces (independent draws)",
              scene_label.c_str(), sha256_hex(plan.scene_json).substr(0, 12).c_str());
  print_box(box);
}

struct RunOptions {
  std::string plan, db, scene_path, shard = "0/1", simulator;
  std::vector<std::string> overrides;
  int jobs = 1, threads = 0;
  long long limit = -1;
  bool retry_failed = false;
  double sample_timeout = 0.0;  // s, 0: none
};

// A progress bar on a terminal, one line per sample otherwise (logs, Slurm output files).
void print_progress(const GenerationProgress& p, const InputSpace& inputs, const Eigen::VectorXd& x, bool terminal) {
  const double rate = static_cast<double>(p.finished) / std::max(p.elapsed_seconds, 1e-9);  // samples per second
  const double eta = static_cast<double>(p.to_run - p.finished) / std::max(rate, 1e-12);
  if (terminal) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * p.finished / std::max<long long>(p.to_run, 1));
    std::fprintf(stderr, "\r[%s%s] %lld/%lld  %lld failed  %.2f samples/min  ETA %s   ", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, '.').c_str(), p.finished, p.to_run, p.failed, 60.0 * rate,
                 duration_text(eta).c_str());
    if (p.finished == p.to_run) std::fprintf(stderr, "\n");
    return;
  }
  std::string where;
  for (size_t j = 0; j < inputs.size(); ++j) {
    where += (j ? ", " : "") + format_human(x(static_cast<Eigen::Index>(j)), inputs[j].kind());
  }
  char mu[48];
  if (p.outcome->converged) {
    std::snprintf(mu, sizeof mu, "mu %.5f", p.outcome->mu);
  } else {
    std::snprintf(mu, sizeof mu, "FAILED");
  }
  std::printf("sample %lld/%lld (plan row %lld: %s): %s in %s; ETA %s%s%s\n", p.finished, p.to_run, p.plan_row,
              where.c_str(), mu, duration_text(p.sample_seconds).c_str(), duration_text(eta).c_str(),
              p.outcome->converged ? "" : " — ", p.outcome->converged ? "" : p.outcome->failure_reason.c_str());
  std::fflush(stdout);
}

void run_command(const RunOptions& o) {
  Dataset plan = read_dataset_isolated(o.plan);
  if (plan.plan.rows() == 0) throw Error(o.plan + ": has no plan (/plan/inputs is empty); make one with mufric dataset plan");
  const int threads = threads_per_job(o.jobs, o.threads);
  SampleEvaluator evaluate;
  if (o.simulator.empty()) {
    const scene::Scene sc = run_scene(o.scene_path, o.overrides, plan, o.plan);
    plan.scene_json = sc.effective.dump(2);
    evaluate = run::micro_evaluator(sc, plan.inputs, threads, o.sample_timeout);
  } else {
    if (!o.scene_path.empty() || !o.overrides.empty()) throw Error("--simulator runs no scene: leave out --scene and --set");
    plan.scene_json = simulator_scene_json(o.simulator);
    evaluate = simulator_evaluator(o.simulator, plan.inputs);
  }
  GenerationOptions options;
  options.shard = parse_shard(o.shard);
  options.jobs = o.jobs;
  options.limit = o.limit;
  options.retry_failed = o.retry_failed;
  const bool terminal = ::isatty(::fileno(stderr)) != 0;
  options.on_sample = [&](const GenerationProgress& p) {
    print_progress(p, plan.inputs, plan.plan.row(p.plan_row).transpose(), terminal);
  };
  std::printf("%s: shard %s of %s (%s), %s x %s, scene sha256 %s\n", o.db.c_str(), o.shard.c_str(), o.plan.c_str(),
              count_of(plan.plan.rows(), "point", "points").c_str(), count_of(o.jobs, "job", "jobs").c_str(),
              count_of(threads, "thread", "threads").c_str(), sha256_hex(plan.scene_json).substr(0, 12).c_str());
  std::fflush(stdout);
  const GenerationReport r = generate_dataset(plan, o.db, evaluate, options);
  std::printf("%s: %s in this shard, %lld already done, %lld run now (%lld converged, %lld failed) in %s\n", o.db.c_str(),
              count_of(r.planned, "plan row", "plan rows").c_str(), r.already_done, r.ran, r.converged, r.failed,
              duration_text(r.seconds).c_str());
}

struct RefineCommandOptions {
  RefineOptions refine;  // db, budget, batch, candidates, growth, jobs, seed, ...
  std::string simulator;  // a model file standing in for the micro-model ("": the micro-model)
  int threads = 0;
  double sample_timeout = 0.0;  // s, 0: none
};

void refine_command(const RefineCommandOptions& c) {
  RefineOptions o = c.refine;
  // The samples: the micro-model with the database's scene, on the (possibly grown) box's inputs.
  o.make_evaluator = [&c](const Dataset& db) {
    return database_evaluator(db, c.refine.db, c.simulator, threads_per_job(c.refine.jobs, c.threads), c.sample_timeout);
  };
  o.on_box = [&o](const BoxGrowth& g) {
    if (!g.grown) {
      std::printf("%s: the box already covers the candidates of %s (%lld rows); not grown\n", o.db.c_str(),
                  o.candidates_csv.c_str(), g.candidate_rows);
      return;
    }
    std::printf("%s: box %s\n", o.db.c_str(), g.record.c_str());
    std::fflush(stdout);
  };
  o.on_drop = [&o](long long dropped) {
    std::printf("%s: %lld plan rows not yet run left out of the plan (--drop-pending)\n", o.db.c_str(), dropped);
    std::fflush(stdout);
  };
  o.on_round = [](const RefineRound& r) {
    std::printf("round %d: %lld training samples, LOO mean relative error %.3f %%, max %.3f %%", r.round,
                r.training_samples, 100.0 * r.loo_mean_relative_error, 100.0 * r.loo_max_relative_error);
    if (r.held_out != nullptr) {
      std::printf("; held-out (%s, %s) mean %.3f %%, max %.3f %%, 95 %% coverage %.1f %%", r.held_out_source.c_str(),
                  count_of(r.held_out->points, "point", "points").c_str(), 100.0 * r.held_out->mean_relative_error, 100.0 * r.held_out->max_relative_error,
                  100.0 * r.held_out->coverage);
    }
    std::printf("\n");
    std::fflush(stdout);
  };
  o.on_pick = [](const RefinePick& k) {
    if (k.imse_reduction > 0.0) {  // independent draws: picked by the integrated variance it removes
      const std::string what = k.replicates_row >= 0 ? "more draws at plan row " + std::to_string(k.replicates_row) + "'s point"
                                                     : std::string("a new point");
      std::printf("  pick %zu: plan row %lld, %s, std of the mean there %.4f, removes %.3g of the mean variance over "
                  "the box\n", k.number, k.plan_row, what.c_str(), k.std_at_pick, k.imse_reduction);
      return;
    }
    std::printf("  pick %zu: plan row %lld, predicted std %.4f\n", k.number, k.plan_row, k.std_at_pick);
  };
  o.on_sample = [](const GenerationProgress& p, const InputSpace& inputs, const Eigen::VectorXd& x) {
    print_progress(p, inputs, x, false);
  };
  const RefineReport r = refine_dataset(o);
  std::printf("%s: %lld micro-model runs spent of a budget of %lld%s%s\n", o.db.c_str(), r.spent, o.budget,
              o.model_out.empty() ? "" : "; final model ", o.model_out.c_str());
}

// What a database holds: provenance, how much of its plan is done, why samples failed.
void status_command(const std::string& path) {
  const Dataset d = read_dataset_isolated(path);
  long long converged = 0, outside = 0, with_std = 0;
  std::map<std::string, long long> reasons, outside_reasons;
  std::set<long long> answered;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (d.converged(i)) {
      ++converged;
      with_std += std::isfinite(d.mu_std(i));
    } else if (d.outside_model(i)) {
      ++outside;
      ++outside_reasons[d.failure_reason[static_cast<size_t>(i)].substr(0, 120)];
    } else {
      ++reasons[d.failure_reason[static_cast<size_t>(i)].substr(0, 120)];
    }
    if (!d.plan_index.empty()) answered.insert(d.plan_index[static_cast<size_t>(i)]);
  }
  std::printf("%s: %s\n  code %s, created %s, scene sha256 %s\n", path.c_str(), d.source.c_str(), d.code_version.c_str(),
              d.created_utc.c_str(), d.scene_json.empty() ? "(none)" : sha256_hex(d.scene_json).substr(0, 12).c_str());
  std::printf("  plan: %s%s%s", count_of(static_cast<long long>(d.plan.rows()), "point", "points").c_str(), d.plan_design.empty() ? "" : ", design ",
              d.plan_design.c_str());
  if (!d.plan_design.empty()) std::printf(" (seed %lld)", d.plan_seed);
  std::printf("; draws %s", d.draws == DrawDesign::independent ? "independent (every row its own tool and chip surfaces)"
                            : d.draws == DrawDesign::common    ? "common (every row the scene's own surfaces)"
                                                               : "common (a file from before draws were recorded)");
  std::printf("\n  samples: %lld (%lld converged, %lld outside the model, %lld failed)", static_cast<long long>(d.size()),
              converged, outside, static_cast<long long>(d.size()) - converged - outside);
  if (!d.plan_index.empty() || d.size() == 0) {
    std::printf("; %lld of %lld plan points not yet run", static_cast<long long>(d.plan.rows()) - static_cast<long long>(answered.size()),
                static_cast<long long>(d.plan.rows()));
  }
  std::printf("\n");
  print_box(d.inputs);
  for (const auto& change : d.box_history) std::printf("  box %s\n", change.c_str());
  if (converged > 0) {
    double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < d.size(); ++i) {
      if (!d.converged(i)) continue;
      lo = std::min(lo, d.mu(i));
      hi = std::max(hi, d.mu(i));
    }
    std::printf("  mu: %.5f .. %.5f; %lld of %lld converged samples carry their standard error\n", lo, hi, with_std, converged);
  }
  if (d.draw_mu.cols() > 0 && converged > 0) {
    // The per-draw spread (the patch scatter a model trained on these data will serve), from the
    // converged samples' own draws.
    std::vector<double> spreads;
    long long draws = 0;
    for (Eigen::Index i = 0; i < d.size(); ++i) {
      if (!d.converged(i)) continue;
      const Eigen::ArrayXd row = d.draw_mu.row(i).transpose().array();
      const Eigen::Index r = row.isFinite().count();
      draws += r;
      if (r < 2) continue;
      const double mean = row.isFinite().select(row, 0.0).sum() / static_cast<double>(r);
      const double squares = row.isFinite().select((row - mean).square(), 0.0).sum();
      spreads.push_back(std::sqrt(squares / static_cast<double>(r - 1)) / std::max(std::abs(mean), 1e-300));
    }
    std::printf("  draws: %lld in %lld converged samples", draws, converged);
    if (!spreads.empty()) {
      std::nth_element(spreads.begin(), spreads.begin() + static_cast<std::ptrdiff_t>(spreads.size() / 2), spreads.end());
      std::printf("; per-draw standard deviation of mu, median over the samples %.1f %% of their mu", 100.0 * spreads[spreads.size() / 2]);
    }
    std::printf("\n");
  }
  if (!d.note.empty()) std::printf("  note: %s\n", d.note.c_str());
  if (const std::optional<double> total = total_wall_seconds(d)) {
    std::printf("  micro-model time: %s in total, %s per sample\n", duration_text(*total).c_str(),
                duration_text(*total / static_cast<double>(d.size())).c_str());
  }
  for (const auto& [reason, count] : reasons) std::printf("  failed x%lld: %s\n", count, reason.c_str());
  for (const auto& [reason, count] : outside_reasons) {
    std::printf("  outside the model (not trained on) x%lld: %s\n", count, reason.c_str());
  }
}

struct MergeOptions {
  std::vector<std::string> inputs;
  std::string out;
  bool allow_mixed = false;
};

void merge_command(const MergeOptions& o) {
  MergeReport r;
  const Dataset merged = merge_datasets(o.inputs, o.allow_mixed, r);
  write_dataset(o.out, merged);
  std::printf("wrote %s: %s, %lld samples read, %s removed -> %s (%lld converged, %lld failed); %lld of %s not "
              "yet run\n",
              o.out.c_str(), count_of(r.files, "file", "files").c_str(), r.samples_read,
              count_of(r.duplicates_removed, "duplicate", "duplicates").c_str(),
              count_of(r.converged + r.failed, "sample", "samples").c_str(), r.converged, r.failed, r.plan_rows_missing,
              count_of(r.plan_rows, "plan row", "plan rows").c_str());
}

}  // namespace

void add_dataset_commands(CLI::App& app) {
  CLI::App* dataset = app.get_subcommand("dataset");

  auto p = std::make_shared<PlanOptions>();
  auto* plan = dataset->add_subcommand("plan", "A sampling plan over the (p, v, T) box, and any law coefficient given a range, for micro-model runs");
  plan->add_option("--out", p->out, "Plan file to write (HDF5, a dataset with no samples yet)")->required();
  plan->add_option("--samples", p->samples, "Number of points")->capture_default_str()->check(CLI::Range(1LL, 10000000LL));
  plan->add_option("--design", p->design, "sobol, lhs (Latin hypercube) or random")->capture_default_str();
  plan->add_option("--seed", p->seed, "Seed (Sobol: 0 = unshifted, else a random digital shift)")->capture_default_str();
  for (const InputSpec& input : default_friction_box()) {  // --p, --v, --T
    const std::string flag(flag_of(input.name));
    plan->add_option(flag, p->ranges[flag],
                     "Range of " + input.name + ", e.g. " + format_human(input.lo, input.kind()) + ":" +
                         format_human(input.hi, input.kind()) + " (default: that, seed 000's box)");
  }
  for (const scene::SettableInput* coefficient : law_coefficient_inputs()) {  // --shear-factor, ...
    const std::string flag(flag_of(coefficient->input));
    plan->add_option(flag, p->ranges[flag],
                     "Vary the interface law's " + std::string(coefficient->input) + " (" + coefficient->scene_key +
                         ") over lo:hi, e.g. 0.2:0.9, as an input after p, v, T (a calibration campaign); the scene's "
                         "law must read it");
  }
  plan->add_option("--box-from", p->box_from,
                   "A measurement file (the rows calibrate reads, e.g. mufric measurements' output): the p, v, T box is "
                   "its conditions' range (+-2 SD where uncertain) widened by --box-margin; --p, --v, --T still override")
      ->check(CLI::ExistingFile);
  plan->add_option("--box-margin", p->box_margin, "With --box-from: the share of each condition's width added on each side "
                                                  "(pressure and velocity in log)")
      ->capture_default_str()
      ->check(FiniteRange(0.0, 10.0));
  plan->add_option("--scene", p->scene_path, "Scene file (JSON) stored with the plan; default: the default dry scene")
      ->check(CLI::ExistingFile);
  plan->add_option("--set", p->overrides, "Override a scene value, e.g. --set time.duration=100ns (repeatable)");
  plan->add_flag("--common-tools", p->common_tools,
                 "Every row on the scene's own tool and chip surfaces (common random numbers), as before issue 33: "
                 "for a trend or a difference between scenes, where shared surfaces cancel. Default: every row its "
                 "own surfaces, drawn from seeds derived from --seed and the row, so that their scatter averages out "
                 "over the campaign and the model's interval shrinks with it");
  plan->footer("Every planned point is kept in the file, so a database made from it accounts for each one.");
  plan->callback([p] { plan_command(*p); });

  auto r = std::make_shared<RunOptions>();
  auto* run = dataset->add_subcommand("run", "Run the micro-model at every plan point of a shard into a database");
  run->add_option("--plan", r->plan, "Plan file (mufric dataset plan)")->required()->check(CLI::ExistingFile);
  run->add_option("--db", r->db, "Database to fill (HDF5); created, or resumed if it exists")->required();
  run->add_option("--scene", r->scene_path, "Scene file instead of the plan's own")->check(CLI::ExistingFile);
  run->add_option("--set", r->overrides, "Override a scene value (repeatable)");
  run->add_option("--shard", r->shard, "This process's share i/N of the plan: rows r with r mod N = i")->capture_default_str();
  run->add_option("--jobs", r->jobs, "Samples run at once")->capture_default_str()->check(CLI::Range(1, 1024));
  run->add_option("--threads", r->threads, "Threads per sample (default: cores / jobs)")->check(CLI::Range(1, 1024));
  run->add_option("--limit", r->limit, "Run at most this many samples now")->check(CLI::Range(1LL, 10000000LL));
  run->add_flag("--retry-failed", r->retry_failed, "Run failed samples again (their old record is replaced)");
  run->add_option("--simulator", r->simulator,
                  "A model file whose mu stands in for the micro-model (a law from mufric law, say): the campaign's\n"
                  "machinery (run, refine, train, learn) in seconds. The database's scene then names it, so its\n"
                  "samples never mix with the micro-model's")
      ->check(CLI::ExistingFile);
  run->add_option("--sample-timeout", r->sample_timeout,
                  "Stop a sample still running after this many seconds and record it as failed, with where it stopped "
                     "(0: no limit). A corner of the box where the solver crawls then costs a shard this long, not hours")
      ->capture_default_str()->check(FiniteRange(0.0, 1e7));
  run->footer("The database is rewritten atomically after every sample: a killed run loses only the samples in\n"
              "flight, and running the same command again skips every finished plan row. A sample whose run does\n"
              "not converge is recorded as failed with its reason. Shards write separate databases; combine them\n"
              "with mufric dataset merge.");
  run->callback([r] { run_command(*r); });

  auto f = std::make_shared<RefineCommandOptions>();
  auto* refine = dataset->add_subcommand(
      "refine", "Active learning: run the micro-model where the surrogate is least certain, retrain, repeat");
  refine->add_option("--db", f->refine.db, "Micro-model database to extend (from dataset plan + run)")->required()->check(CLI::ExistingFile);
  refine->add_option("--budget", f->refine.budget, "Micro-model runs to spend")->required()->check(CLI::Range(0LL, 1000000LL));
  refine->add_option("--batch", f->refine.batch, "Runs per round (picked jointly, then run, then the GP is retrained)")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  refine->add_option("--test", f->refine.test, "Held-out database: its error is reported after every round")->check(CLI::ExistingFile);
  auto* candidates = refine->add_option("--candidates", f->refine.candidates_csv,
                                        "CSV of extra candidate points with unit headers, e.g. the server's "
                                        "--log-uncertain file (rows outside the box are left out unless --grow-box)")
                          ->check(CLI::ExistingFile);
  refine->add_flag("--grow-box", f->refine.grow,
                   "First grow the plan's box toward the --candidates rows outside it (where the meso code asks); "
                   "the new box is recorded in the database (/plan/box_history, shown by dataset status)")
      ->needs(candidates);
  refine->add_option("--grow-coverage", f->refine.grow_coverage,
                     "With --grow-box: cover this quantile of the outside rows per input and side (0.99 ignores the "
                     "farthest 1 %, e.g. a meso code's spikes)")
      ->capture_default_str()->check(FiniteRange(1e-3, 1.0));
  refine->add_option("--candidate-count", f->refine.candidate_count, "Sobol' candidates per round")->capture_default_str()
      ->check(CLI::Range(16LL, 100000LL));
  refine->add_option("--model-out", f->refine.model_out, "Write the GP trained after each round here");
  refine->add_option("--jobs", f->refine.jobs, "Runs at once")->capture_default_str()->check(CLI::Range(1, 1024));
  refine->add_option("--threads", f->threads, "Threads per run (default: cores / jobs)")->check(CLI::Range(1, 1024));
  refine->add_option("--restarts", f->refine.restarts, "GP optimiser restarts per round")->capture_default_str();
  refine->add_option("--simulator", f->simulator, "The model file a simulator's database was run with (dataset run --simulator)")
      ->check(CLI::ExistingFile);
  refine->add_option("--sample-timeout", f->sample_timeout,
                     "Stop a run still going after this many seconds and record it as failed (0: no limit)")
      ->capture_default_str()->check(FiniteRange(0.0, 1e7));
  refine->add_option("--seed", f->refine.seed, "Seed of the candidate sets and GP restarts")->capture_default_str();
  refine->add_flag("--drop-pending", f->refine.drop_pending,
                   "First leave the plan rows not yet run out of the plan (they must all follow the last row run),\n"
                   "so that the budget goes to the picks: a campaign that ran a prefix of its plan hands over");
  refine->footer("Each round trains a GP on the converged samples, picks --batch candidates by the largest posterior\n"
                 "variance (each pick conditioning the next), appends them to the plan, runs them with the database's\n"
                 "scene, and reports the leave-one-out error (and the held-out error with --test).\n"
                 "A database of independent draws (dataset plan's default) is trained by stochastic kriging, and each\n"
                 "pick is the candidate that removes the most variance of the mean over the box (IMSE): a new point,\n"
                 "or more draws at a point already run (a new plan row there, with its own surfaces), whichever the\n"
                 "patch scatter there and the data around it make worth more.");
  refine->callback([f] { refine_command(*f); });

  auto s = std::make_shared<std::string>();
  auto* status = dataset->add_subcommand("status", "What a dataset file holds: provenance, plan progress, failures");
  status->add_option("db", *s, "Dataset file (HDF5)")->required()->check(CLI::ExistingFile);
  status->callback([s] { status_command(*s); });

  auto m = std::make_shared<MergeOptions>();
  auto* merge = dataset->add_subcommand("merge", "Combine shard databases of one plan");
  merge->add_option("inputs", m->inputs, "Shard databases")->required()->check(CLI::ExistingFile);
  merge->add_option("--out", m->out, "Merged database to write")->required();
  merge->add_flag("--allow-mixed", m->allow_mixed, "Merge databases made with different scenes or code versions");
  merge->callback([m] { merge_command(*m); });
}

}  // namespace mufric::app
