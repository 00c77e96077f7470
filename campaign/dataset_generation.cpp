#include "campaign/dataset_generation.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <mutex>
#include <set>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/version.hpp"
#include "common/work_pool.hpp"

namespace mufric {

Shard parse_shard(const std::string& text, const std::string& field) {
  const auto slash = text.find('/');
  Shard s;
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    size_t used = 0;
    s.index = std::stoll(text.substr(0, slash), &used);
    if (used != slash) throw std::invalid_argument("index");
    const std::string count = text.substr(slash + 1);
    s.count = std::stoll(count, &used);
    if (used != count.size()) throw std::invalid_argument("count");
  } catch (const std::exception&) {
    throw Error(field + " '" + text + "': give i/N, e.g. 0/4");
  }
  if (s.count < 1 || s.index < 0 || s.index >= s.count) {
    throw Error(field + " '" + text + "': needs N >= 1 and 0 <= i < N");
  }
  return s;
}

namespace {

// Equal plans (a shape check first: Eigen compares matrices of equal shape only).
bool same_plan(const h5::RowMatrix& a, const h5::RowMatrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a == b;
}

// SplitMix64's output function (Steele, Lea & Flood 2014; Vigna's reference constants).
std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

constexpr std::uint64_t kRowSeedMask = (std::uint64_t{1} << 30) - 1;

}  // namespace

DrawSeeds row_draw_seeds(long long plan_seed, long long row) {
  const std::uint64_t h = splitmix64(static_cast<std::uint64_t>(plan_seed) ^ splitmix64(static_cast<std::uint64_t>(row)));
  return {h & kRowSeedMask, (h >> 32) & kRowSeedMask};
}

std::vector<bool> answered_plan_rows(const Dataset& db) {
  std::vector<bool> answered(static_cast<size_t>(db.plan.rows()), false);
  for (const long long row : db.plan_index) {
    if (row >= 0 && row < db.plan.rows()) answered[static_cast<size_t>(row)] = true;
  }
  return answered;
}

Dataset empty_dataset(const Dataset& plan) {
  Dataset d;
  d.inputs = plan.inputs;
  d.x.resize(0, static_cast<Eigen::Index>(plan.inputs.size()));
  d.mu.resize(0);
  d.mu_std.resize(0);
  d.plan = plan.plan;
  d.plan_design = plan.plan_design;
  d.plan_seed = plan.plan_seed;
  d.draws = plan.draws;
  d.draw_mu.resize(0, 0);
  d.box_history = plan.box_history;
  d.source = plan.source;
  d.scene_json = plan.scene_json;
  d.code_version = code_version();
  d.created_utc = utc_timestamp();  // once: every later write keeps it
  return d;
}

Dataset open_database(const std::string& db_path, const Dataset& plan) {
  if (plan.plan.rows() == 0) throw Error("the plan has no points (/plan/inputs is empty)");
  if (!std::filesystem::exists(db_path)) return empty_dataset(plan);
  Dataset d = read_dataset_isolated(db_path);
  if (const std::string difference = input_space_difference(d.inputs, db_path, plan.inputs, "the plan");
      !difference.empty()) {
    throw Error(db_path + ": its inputs or box differ from the plan's: " + difference);
  }
  if (!same_plan(d.plan, plan.plan)) {
    throw Error(db_path + ": was made from a different plan (" + std::to_string(d.plan.rows()) + " rows, the plan has " +
                std::to_string(plan.plan.rows()) + " or different points); use another --db");
  }
  if (d.scene_json != plan.scene_json) {
    throw Error(db_path + ": was made with a different scene (sha256 " + sha256_hex(d.scene_json).substr(0, 12) +
                ", now " + sha256_hex(plan.scene_json).substr(0, 12) + "); use another --db");
  }
  if (d.draws != plan.draws || d.plan_seed != plan.plan_seed) {
    throw Error(db_path + ": draws its roughness differently from the plan (draws '" + std::string(draw_design_name(d.draws)) +
                "', plan seed " + std::to_string(d.plan_seed) + "; the plan: '" + draw_design_name(plan.draws) + "', " +
                std::to_string(plan.plan_seed) + "); use another --db");
  }
  if (d.plan_index.size() != static_cast<size_t>(d.size())) throw Error(db_path + ": has samples without plan rows");
  return d;
}

void append_sample(Dataset& d, const Eigen::VectorXd& x, long long plan_row, const SampleOutcome& outcome,
                   const std::optional<DrawSeeds>& seeds) {
  const Eigen::Index n = d.size();
  d.tool_seed.resize(static_cast<size_t>(n), -1);
  d.chip_seed.resize(static_cast<size_t>(n), -1);
  d.tool_seed.push_back(seeds ? static_cast<long long>(seeds->tool) : -1);
  d.chip_seed.push_back(seeds ? static_cast<long long>(seeds->chip) : -1);
  const auto draws = static_cast<Eigen::Index>(outcome.draw_mu.size());
  const Eigen::Index columns = std::max(d.draw_mu.cols(), draws);
  h5::RowMatrix draw_mu = h5::RowMatrix::Constant(n + 1, columns, std::numeric_limits<double>::quiet_NaN());
  if (d.draw_mu.rows() == n) draw_mu.topLeftCorner(n, d.draw_mu.cols()) = d.draw_mu;
  for (Eigen::Index k = 0; k < draws; ++k) draw_mu(n, k) = outcome.draw_mu[static_cast<size_t>(k)];
  d.draw_mu = std::move(draw_mu);
  d.x.conservativeResize(n + 1, Eigen::NoChange);
  d.x.row(n) = x.transpose();
  d.mu.conservativeResize(n + 1);
  const bool has_values = outcome.converged || outcome.keep_values_when_failed;
  d.mu(n) = has_values ? outcome.mu : std::numeric_limits<double>::quiet_NaN();
  if (d.mu_std.size() != n) d.mu_std = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  d.mu_std.conservativeResize(n + 1);
  d.mu_std(n) = has_values ? outcome.mu_std : std::numeric_limits<double>::quiet_NaN();
  // A completed run with warnings (a molten chip) is kept, with its μ, but outside the model: the
  // warnings are its reason, and training leaves it out.
  const bool outside = outcome.converged && !outcome.warnings.empty();
  d.status.push_back(static_cast<long long>(!outcome.converged ? SampleStatus::failed
                                            : outside          ? SampleStatus::outside_model
                                                               : SampleStatus::converged));
  std::string reason = outcome.converged ? "" : outcome.failure_reason;
  for (const auto& w : outcome.warnings) reason += (reason.empty() ? "" : "; ") + w;
  d.failure_reason.push_back(reason);
  d.plan_index.push_back(plan_row);
  for (auto& [name, values] : d.diagnostics) {
    values.conservativeResize(n + 1);
    const auto it = outcome.diagnostics.find(name);
    values(n) = it != outcome.diagnostics.end() ? it->second : std::numeric_limits<double>::quiet_NaN();
  }
  for (const auto& [name, value] : outcome.diagnostics) {
    if (d.diagnostics.count(name)) continue;
    Eigen::VectorXd values = Eigen::VectorXd::Constant(n + 1, std::numeric_limits<double>::quiet_NaN());
    values(n) = value;
    d.diagnostics[name] = values;
  }
}

namespace {

// Removes the samples answering `rows` (failed ones about to be retried).
void remove_rows(Dataset& d, const std::set<long long>& rows) {
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (!rows.count(d.plan_index[static_cast<size_t>(i)])) keep.push_back(i);
  }
  Dataset k = d;
  const auto m = static_cast<Eigen::Index>(keep.size());
  k.x.resize(m, d.x.cols());
  k.mu.resize(m);
  k.mu_std.resize(m);
  k.status.clear();
  k.failure_reason.clear();
  k.plan_index.clear();
  k.tool_seed.clear();
  k.chip_seed.clear();
  k.draw_mu.resize(m, d.draw_mu.cols());
  for (auto& [name, values] : k.diagnostics) values.resize(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Index i = keep[static_cast<size_t>(r)];
    k.x.row(r) = d.x.row(i);
    k.mu(r) = d.mu(i);
    k.mu_std(r) = d.mu_std.size() == d.size() ? d.mu_std(i) : std::numeric_limits<double>::quiet_NaN();
    k.status.push_back(d.status[static_cast<size_t>(i)]);
    k.failure_reason.push_back(d.failure_reason[static_cast<size_t>(i)]);
    k.plan_index.push_back(d.plan_index[static_cast<size_t>(i)]);
    if (!d.tool_seed.empty()) k.tool_seed.push_back(d.tool_seed[static_cast<size_t>(i)]);
    if (!d.chip_seed.empty()) k.chip_seed.push_back(d.chip_seed[static_cast<size_t>(i)]);
    if (d.draw_mu.cols() > 0) k.draw_mu.row(r) = d.draw_mu.row(i);
    for (auto& [name, values] : k.diagnostics) values(r) = d.diagnostics.at(name)(i);
  }
  d = std::move(k);
}

}  // namespace

GenerationReport generate_dataset(const Dataset& plan, const std::string& db_path, const SampleEvaluator& evaluate,
                                  const GenerationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.jobs < 1) throw Error("--jobs must be at least 1");
  Dataset db = open_database(db_path, plan);
  GenerationReport report;
  std::set<long long> done, failed_rows;
  for (Eigen::Index i = 0; i < db.size(); ++i) {
    const long long row = db.plan_index[static_cast<size_t>(i)];
    const bool failed = db.failed(i);  // a sample outside the model would only melt again
    if (failed && options.retry_failed) {
      failed_rows.insert(row);
    } else {
      done.insert(row);
    }
  }
  if (!failed_rows.empty()) remove_rows(db, failed_rows);
  std::vector<long long> pending;
  for (long long row = 0; row < plan.plan.rows(); ++row) {
    if (row % options.shard.count != options.shard.index) continue;
    ++report.planned;
    if (done.count(row)) {
      ++report.already_done;
    } else if (options.limit < 0 || static_cast<long long>(pending.size()) < options.limit) {
      pending.push_back(row);
    }
  }
  write_dataset(db_path, db);  // the database exists (and is valid) before the first sample finishes

  // `jobs` workers take the pending rows in order; a failed write stops them (the database on disk
  // keeps every sample written before it).
  std::mutex lock;
  bool write_failed = false;
  std::exception_ptr write_failure;
  run_work_pool(pending.size(), options.jobs, [&](size_t k) {
    const long long row = pending[k];
    SampleRequest request;
    request.x = plan.plan.row(row).transpose();
    request.plan_row = row;
    if (plan.draws == DrawDesign::independent) request.seeds = row_draw_seeds(plan.plan_seed, row);
    const Eigen::VectorXd& x = request.x;
    const auto sample_start = std::chrono::steady_clock::now();
    SampleOutcome outcome;
    try {
      outcome = evaluate(request);
      if (outcome.converged && !std::isfinite(outcome.mu)) {
        outcome.converged = false;
        outcome.failure_reason = "the evaluator returned a non-finite mu";
      }
    } catch (const std::exception& e) {
      outcome = SampleOutcome{};
      outcome.failure_reason = std::string("exception: ") + e.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sample_start).count();
    outcome.diagnostics["wall_seconds"] = seconds;
    std::lock_guard<std::mutex> guard(lock);
    if (write_failed) return false;
    try {
      append_sample(db, x, row, outcome, request.seeds);
      write_dataset(db_path, db);
    } catch (...) {
      write_failure = std::current_exception();
      write_failed = true;
      return false;
    }
    ++report.ran;
    (outcome.converged ? report.converged : report.failed) += 1;
    if (options.on_sample) {
      GenerationProgress p;
      p.finished = report.ran;
      p.to_run = static_cast<long long>(pending.size());
      p.failed = report.failed;
      p.plan_row = row;
      p.outcome = &outcome;
      p.sample_seconds = seconds;
      p.elapsed_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      options.on_sample(p);
    }
    return true;
  });
  if (write_failure) std::rethrow_exception(write_failure);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

Dataset merge_datasets(const std::vector<std::string>& paths, bool allow_mixed, MergeReport& report) {
  if (paths.empty()) throw Error("merge: no input files");
  report = MergeReport{};
  std::vector<Dataset> files;
  for (const auto& path : paths) {
    files.push_back(read_dataset_isolated(path));
    const Dataset& d = files.back();
    const Dataset& first = files.front();
    if (const std::string difference = input_space_difference(d.inputs, path, first.inputs, paths[0]);
        !difference.empty()) {
      throw Error("merge: " + path + ": inputs or box differ from " + paths[0] + "'s: " + difference);
    }
    if (!same_plan(d.plan, first.plan)) throw Error("merge: " + path + ": comes from a different plan than " + paths[0]);
    if (!allow_mixed && d.scene_json != first.scene_json) {
      throw Error("merge: " + path + ": made with a different scene than " + paths[0] + " (--allow-mixed to merge anyway)");
    }
    if (d.draws != first.draws || d.plan_seed != first.plan_seed) {
      throw Error("merge: " + path + ": its plan draws its roughness differently from " + paths[0] + "'s (draws " +
                  draw_design_name(d.draws) + ", plan seed " + std::to_string(d.plan_seed) + " against " +
                  draw_design_name(first.draws) + ", " + std::to_string(first.plan_seed) + ")");
    }
    if (!allow_mixed && d.code_version != first.code_version) {
      throw Error("merge: " + path + ": made by code version " + d.code_version + ", " + paths[0] + " by " +
                  first.code_version + " (--allow-mixed to merge anyway)");
    }
    if (d.plan_index.size() != static_cast<size_t>(d.size())) throw Error("merge: " + path + ": samples without plan rows");
  }
  report.files = static_cast<long long>(files.size());
  // One sample per plan row: the first one read, unless a later one converged where it failed.
  const auto converged = [&](std::pair<size_t, Eigen::Index> at) {
    return files[at.first].converged(at.second);
  };
  std::map<long long, std::pair<size_t, Eigen::Index>> chosen;  // plan row -> (file, sample)
  for (size_t f = 0; f < files.size(); ++f) {
    for (Eigen::Index i = 0; i < files[f].size(); ++i) {
      ++report.samples_read;
      const auto [it, inserted] = chosen.try_emplace(files[f].plan_index[static_cast<size_t>(i)], f, i);
      if (inserted) continue;
      ++report.duplicates_removed;
      if (!converged(it->second) && converged({f, i})) it->second = {f, i};
    }
  }
  Dataset merged = empty_dataset(files.front());
  merged.code_version = files.front().code_version;
  merged.created_utc = files.front().created_utc;
  for (const auto& [row, at] : chosen) {
    const Dataset& d = files[at.first];
    const Eigen::Index i = at.second;
    SampleOutcome o;
    o.converged = !d.failed(i);
    o.keep_values_when_failed = true;  // as the file holds them: NaN for a run that failed, μ for a quarantined one
    o.mu = d.mu(i);
    o.mu_std = d.mu_std(i);
    if (d.failed(i)) o.failure_reason = d.failure_reason[static_cast<size_t>(i)];
    if (d.outside_model(i)) o.warnings = {d.failure_reason[static_cast<size_t>(i)]};
    for (const auto& [name, values] : d.diagnostics) o.diagnostics[name] = values(i);
    for (Eigen::Index k = 0; k < d.draw_mu.cols(); ++k) o.draw_mu.push_back(d.draw_mu(i, k));  // padding included
    std::optional<DrawSeeds> seeds;
    if (!d.tool_seed.empty() && d.tool_seed[static_cast<size_t>(i)] >= 0) {
      seeds = DrawSeeds{static_cast<std::uint64_t>(d.tool_seed[static_cast<size_t>(i)]),
                        static_cast<std::uint64_t>(d.chip_seed[static_cast<size_t>(i)])};
    }
    append_sample(merged, d.x.row(i).transpose(), row, o, seeds);
    (o.converged ? report.converged : report.failed) += 1;
  }
  report.plan_rows = merged.plan.rows();
  report.plan_rows_missing = report.plan_rows - static_cast<long long>(chosen.size());
  if (allow_mixed) merged.source += " (merged with --allow-mixed)";
  return merged;
}

}  // namespace mufric
