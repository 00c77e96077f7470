// `mufric dataset plan / run / merge`: the micro-model as a dataset factory.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.hpp"
#include "common/dataset_generation.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "micro/scene/dataset_sample.hpp"
#include "micro/scene/micro_run.hpp"
#include "surrogate/sampling.hpp"

namespace mufric::app {
namespace {

// "300MPa:1300MPa" → {lo, hi} in SI.
std::pair<double, double> parse_range(const std::string& text, QuantityKind kind, const std::string& flag) {
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw Error(flag + " '" + text + "': give lo:hi with units, e.g. 300MPa:1300MPa");
  const double lo = parse_quantity(text.substr(0, colon), kind, flag);
  const double hi = parse_quantity(text.substr(colon + 1), kind, flag);
  if (!(lo < hi)) throw Error(flag + " '" + text + "': the lower end must lie below the upper end");
  return {lo, hi};
}

std::string duration_text(double seconds) {
  char text[32];
  if (!std::isfinite(seconds)) return "?";
  if (seconds < 90) {
    std::snprintf(text, sizeof text, "%.0fs", seconds);
  } else if (seconds < 5400) {
    std::snprintf(text, sizeof text, "%.0fm%02.0fs", std::floor(seconds / 60), std::fmod(seconds, 60.0));
  } else {
    std::snprintf(text, sizeof text, "%.0fh%02.0fm", std::floor(seconds / 3600), std::fmod(seconds / 60, 60.0));
  }
  return text;
}

struct PlanOptions {
  std::string out, design = "sobol", scene_path, p, v, t;
  std::vector<std::string> overrides;
  long long samples = 64;
  unsigned long long seed = 0;
};

void plan_command(const PlanOptions& o) {
  InputSpace box = default_friction_box();
  const std::map<std::string, const std::string*> ranges{
      {"contact_pressure", &o.p}, {"sliding_velocity", &o.v}, {"temperature", &o.t}};
  const std::map<std::string, std::string> flags{{"contact_pressure", "--p"}, {"sliding_velocity", "--v"}, {"temperature", "--T"}};
  for (auto& input : box) {
    const std::string& text = *ranges.at(input.name);
    if (!text.empty()) std::tie(input.lo, input.hi) = parse_range(text, input.kind(), flags.at(input.name));
  }
  const scene::Scene sc = scene::load_scene(o.scene_path, o.overrides);
  scene::micro_evaluator(sc, box, 1);  // refuses a scene the dataset cannot drive, before anything is written
  const PlanDesign design = parse_plan_design(o.design);
  Dataset plan;
  plan.inputs = box;
  plan.x.resize(0, static_cast<Eigen::Index>(box.size()));
  plan.mu.resize(0);
  plan.plan = plan_in_box(design, o.samples, box, o.seed);
  plan.plan_design = plan_design_name(design);
  plan.plan_seed = static_cast<long long>(o.seed);
  plan.scene_json = sc.effective.dump(2);
  plan.source = "micro-model plan (" + sc.source + ")";
  plan.plan_index.clear();
  write_dataset(o.out, plan);
  std::printf("wrote %s: %lld points, %s design (seed %llu), scene %s (sha256 %s)\n", o.out.c_str(), o.samples,
              plan.plan_design.c_str(), o.seed, sc.source.c_str(), sha256_hex(plan.scene_json).substr(0, 12).c_str());
  for (const auto& input : box) {
    std::printf("  %-17s %s .. %s\n", input.name.c_str(), format_human(input.lo, input.kind()).c_str(),
                format_human(input.hi, input.kind()).c_str());
  }
}

struct RunOptions {
  std::string plan, db, scene_path, shard = "0/1";
  std::vector<std::string> overrides;
  int jobs = 1, threads = 0;
  long long limit = -1;
  bool retry_failed = false;
};

// A progress bar on a terminal, one line per sample otherwise (logs, Slurm output files).
void print_progress(const GenerationProgress& p, const InputSpace& inputs, const Eigen::VectorXd& x, bool terminal) {
  const double rate = p.finished / std::max(p.elapsed_seconds, 1e-9);  // samples per second
  const double eta = (p.to_run - p.finished) / std::max(rate, 1e-12);
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
  Dataset plan = read_dataset(o.plan);
  if (plan.plan.rows() == 0) throw Error(o.plan + ": has no plan (/plan/inputs is empty); make one with mufric dataset plan");
  // The scene: --scene (or the plan's own), then --set.
  nlohmann::json scene_json;
  std::string scene_source;
  if (!o.scene_path.empty()) {
    scene_json = scene::read_scene_json(o.scene_path);
    scene_source = o.scene_path;
  } else if (!plan.scene_json.empty()) {
    scene_json = nlohmann::json::parse(plan.scene_json);
    scene_source = "the scene of " + o.plan;
  } else {
    scene_json = scene::default_scene_json();
    scene_source = "default dry scene";
  }
  for (const auto& assignment : o.overrides) scene::apply_override(scene_json, assignment);
  const std::string base = o.scene_path.empty() ? "." : std::filesystem::path(o.scene_path).parent_path().string();
  const scene::Scene sc = scene::parse_scene(scene_json, scene_source, base.empty() ? "." : base);
  plan.scene_json = sc.effective.dump(2);

  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = o.threads > 0 ? o.threads : std::max(1, cores / o.jobs);
  const SampleEvaluator evaluate = scene::micro_evaluator(sc, plan.inputs, threads);
  GenerationOptions options;
  options.shard = parse_shard(o.shard);
  options.jobs = o.jobs;
  options.limit = o.limit;
  options.retry_failed = o.retry_failed;
  const bool terminal = ::isatty(::fileno(stderr)) != 0;
  options.on_sample = [&](const GenerationProgress& p) {
    print_progress(p, plan.inputs, plan.plan.row(p.plan_row).transpose(), terminal);
  };
  std::printf("%s: shard %s of %s (%lld points), %d job(s) x %d thread(s), scene sha256 %s\n", o.db.c_str(),
              o.shard.c_str(), o.plan.c_str(), static_cast<long long>(plan.plan.rows()), o.jobs, threads,
              sha256_hex(plan.scene_json).substr(0, 12).c_str());
  std::fflush(stdout);
  const GenerationReport r = generate_dataset(plan, o.db, evaluate, options);
  std::printf("%s: %lld plan rows in this shard, %lld already done, %lld run now (%lld converged, %lld failed) in %s\n",
              o.db.c_str(), r.planned, r.already_done, r.ran, r.converged, r.failed, duration_text(r.seconds).c_str());
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
  std::printf("wrote %s: %lld files, %lld samples read, %lld duplicates removed -> %lld samples (%lld converged, "
              "%lld failed); %lld of %lld plan rows not yet run\n",
              o.out.c_str(), r.files, r.samples_read, r.duplicates_removed, r.converged + r.failed, r.converged,
              r.failed, r.plan_rows_missing, r.plan_rows);
}

}  // namespace

void add_dataset_commands(CLI::App& app) {
  CLI::App* dataset = app.get_subcommand("dataset");

  auto p = std::make_shared<PlanOptions>();
  auto* plan = dataset->add_subcommand("plan", "A sampling plan over the (p, v, T) box for micro-model runs");
  plan->add_option("--out", p->out, "Plan file to write (HDF5, a dataset with no samples yet)")->required();
  plan->add_option("--samples", p->samples, "Number of points")->capture_default_str()->check(CLI::Range(1LL, 10000000LL));
  plan->add_option("--design", p->design, "sobol, lhs (Latin hypercube) or random")->capture_default_str();
  plan->add_option("--seed", p->seed, "Seed (Sobol: 0 = unshifted, else a random digital shift)")->capture_default_str();
  plan->add_option("--p", p->p, "Contact pressure range, e.g. 300MPa:1300MPa (default: seed 000's box)");
  plan->add_option("--v", p->v, "Sliding velocity range, e.g. 22.5m/min:200m/min");
  plan->add_option("--T", p->t, "Temperature range, e.g. 25C:900C");
  plan->add_option("--scene", p->scene_path, "Scene file (JSON) stored with the plan; default: the default dry scene")
      ->check(CLI::ExistingFile);
  plan->add_option("--set", p->overrides, "Override a scene value, e.g. --set time.duration=100ns (repeatable)");
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
  run->footer("The database is rewritten atomically after every sample: a killed run loses only the samples in\n"
              "flight, and running the same command again skips every finished plan row. A sample whose run does\n"
              "not converge is recorded as failed with its reason. Shards write separate databases; combine them\n"
              "with mufric dataset merge.");
  run->callback([r] { run_command(*r); });

  auto m = std::make_shared<MergeOptions>();
  auto* merge = dataset->add_subcommand("merge", "Combine shard databases of one plan");
  merge->add_option("inputs", m->inputs, "Shard databases")->required()->check(CLI::ExistingFile);
  merge->add_option("--out", m->out, "Merged database to write")->required();
  merge->add_flag("--allow-mixed", m->allow_mixed, "Merge databases made with different scenes or code versions");
  merge->callback([m] { merge_command(*m); });
}

}  // namespace mufric::app
