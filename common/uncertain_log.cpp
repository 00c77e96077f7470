#include "common/uncertain_log.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "common/error.hpp"
#include "common/files.hpp"

namespace mufric {
namespace {
constexpr double kZ95 = 1.959963984540054;  // two-sided 95 % normal quantile
// A summary is rewritten at most this often while queries keep falling outside the box.
constexpr auto kSummaryInterval = std::chrono::seconds(1);

// Angles are periodic (the laws and the GP's clamp wrap them), so they are never outside the box.
bool can_be_outside(const InputSpec& input) { return input.kind() != QuantityKind::angle; }

void count_outside(double value, const InputSpec& box, OutsideInputCount& count, bool& outside) {
  if (!can_be_outside(box)) return;
  if (value < box.lo) {
    count.lowest = count.below == 0 ? value : std::min(count.lowest, value);
    ++count.below;
    outside = true;
  } else if (value > box.hi) {
    count.highest = count.above == 0 ? value : std::max(count.highest, value);
    ++count.above;
    outside = true;
  }
}
// The data rows of a log file (its lines but the header; 0 when it does not exist).
long long count_logged_rows(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return 0;
  const auto lines = std::count(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>(), '\n');
  return std::max<long long>(0, static_cast<long long>(lines) - 1);
}
}  // namespace

UncertainQueryLog::UncertainQueryLog(std::string directory, double width_threshold, long long max_rows_per_model)
    : directory_(std::move(directory)), width_threshold_(width_threshold), max_rows_(max_rows_per_model) {
  if (!(width_threshold_ > 0.0)) throw Error("the uncertain-query log's interval width must be positive");
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);
  if (ec) throw Error("uncertain-query log: cannot create '" + directory_ + "': " + ec.message());
}

UncertainQueryLog::~UncertainQueryLog() { flush(); }

std::string UncertainQueryLog::path(const std::string& model) const { return directory_ + "/" + model + ".csv"; }
std::string UncertainQueryLog::rotated_path(const std::string& model) const { return rotated_log_path(path(model)); }
std::string UncertainQueryLog::outside_path(const std::string& model) const {
  return directory_ + "/" + model + ".outside.json";
}

long long UncertainQueryLog::rows(const std::string& model) const {
  std::lock_guard<std::mutex> guard(lock_);
  const auto it = models_.find(model);
  return it == models_.end() ? 0 : it->second.rows;
}

OutsideSummary UncertainQueryLog::outside(const std::string& model) const {
  std::lock_guard<std::mutex> guard(lock_);
  const auto it = models_.find(model);
  return it == models_.end() ? OutsideSummary{} : it->second.outside;
}

void UncertainQueryLog::flush() {
  std::lock_guard<std::mutex> guard(lock_);
  for (auto& [model, log] : models_) {
    if (log.summary_dirty) write_summary(model, log);
  }
}

void UncertainQueryLog::record(const std::string& model, const InputSpace& inputs,
                               const Eigen::Ref<const Eigen::MatrixXd>& x, const Eigen::Ref<const Eigen::VectorXd>& std) {
  std::string text;
  long long added = 0;
  std::lock_guard<std::mutex> guard(lock_);
  ModelLog& log = models_[model];
  // First call, or the model was reloaded with another box: counts against the old box would say
  // nothing about the new one, so they start again (the summary file is then rewritten).
  if (!same_input_space(log.box, inputs)) {  // log.box and the counts are set together, here
    const bool summary_on_disk = log.outside.outside_queries > 0;
    log.outside = {.queries = 0, .outside_queries = 0, .inputs = std::vector<OutsideInputCount>(inputs.size())};
    log.box = inputs;
    log.summary_dirty = log.summary_dirty || summary_on_disk;
  }
  const long long outside_before = log.outside.outside_queries;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (!x.row(i).allFinite()) continue;  // an invalid input, answered with a status, not a place to sample
    ++log.outside.queries;
    int outside_inputs = 0;
    for (size_t j = 0; j < inputs.size(); ++j) {
      bool outside = false;
      count_outside(x(i, static_cast<Eigen::Index>(j)), inputs[j], log.outside.inputs[j], outside);
      outside_inputs += outside;
    }
    log.outside.outside_queries += outside_inputs > 0;
    const double width = 2.0 * kZ95 * std(i);
    if ((!(width > width_threshold_) && outside_inputs == 0) || added >= max_rows_) continue;
    char cell[40];
    for (Eigen::Index j = 0; j < x.cols(); ++j) {
      std::snprintf(cell, sizeof cell, "%s%.17g", j ? "," : "", x(i, j));
      text += cell;
    }
    std::snprintf(cell, sizeof cell, ",%.6g,%d\n", width, outside_inputs);
    text += cell;
    ++added;
  }
  if (log.outside.outside_queries > outside_before) {
    if (outside_before == 0) {
      std::fprintf(stderr, "mufric: %s is asked about points outside its box; counts per input in %s\n",
                   model.c_str(), outside_path(model).c_str());
    }
    log.summary_dirty = true;
  }
  if (log.summary_dirty && std::chrono::steady_clock::now() - log.summary_written >= kSummaryInterval) {
    write_summary(model, log);
  }
  if (added > 0) append_rows(model, log, inputs, text, added);
}

void UncertainQueryLog::append_rows(const std::string& model, ModelLog& log, const InputSpace& inputs,
                                    const std::string& rows_text, long long added) {
  std::string text = rows_text;
  const std::string file = path(model);
  if (!log.rows_counted) {  // a file from an earlier server process counts toward its cap
    log.rows = count_logged_rows(file);
    log.rows_counted = true;
  }
  if (log.rows > 0 && log.rows + added > max_rows_) {
    // Full: renamed to NAME.csv.1 (replacing the one before), so the log's disk use stays bounded
    // while it keeps following the queries; a reader that remembers the file (the learner) finishes
    // the renamed one before it starts on the new one.
    std::error_code ec;
    std::filesystem::rename(file, rotated_path(model), ec);
    if (ec) {
      std::fprintf(stderr, "mufric: cannot rename the full %s (%s); uncertain queries of %s are not logged\n",
                   file.c_str(), ec.message().c_str(), model.c_str());
      return;
    }
    std::fprintf(stderr, "mufric: %s reached %lld logged queries; renamed to %s, a new log begins\n", file.c_str(),
                 log.rows, rotated_path(model).c_str());
    log.rows = 0;
  }
  const bool fresh = !std::filesystem::exists(file) || std::filesystem::file_size(file) == 0;
  if (fresh) {
    std::string header;
    for (size_t j = 0; j < inputs.size(); ++j) header += (j ? "," : "") + inputs[j].name + "[" + inputs[j].unit + "]";
    text = header + ",ci95_width,outside_inputs\n" + text;
  }
  std::ofstream out(file, std::ios::app | std::ios::binary);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));  // one write per batch
  out.flush();
  if (!out) {
    std::fprintf(stderr, "mufric: cannot append to %s; these uncertain queries of %s are not logged\n", file.c_str(),
                 model.c_str());
    return;
  }
  log.rows += added;
}

// The summary as JSON: per input its box and, per side, the count and the farthest value (SI).
void UncertainQueryLog::write_summary(const std::string& model, ModelLog& log) {
  nlohmann::json inputs = nlohmann::json::array();
  for (size_t j = 0; j < log.box.size(); ++j) {
    const OutsideInputCount& c = log.outside.inputs[j];
    nlohmann::json entry = {{"name", log.box[j].name}, {"unit", log.box[j].unit},   {"box_lo", log.box[j].lo},
                            {"box_hi", log.box[j].hi}, {"below", c.below},          {"above", c.above}};
    if (c.below > 0) entry["lowest"] = c.lowest;
    if (c.above > 0) entry["highest"] = c.highest;
    inputs.push_back(entry);
  }
  const nlohmann::json summary = {{"model", model},
                                  {"queries", log.outside.queries},
                                  {"outside_queries", log.outside.outside_queries},
                                  {"inputs", inputs}};
  try {
    write_file_atomically(outside_path(model), summary.dump(2) + "\n");
  } catch (const Error& e) {
    std::fprintf(stderr, "mufric: %s\n", e.what());  // the counts stay in memory and are tried again
    return;
  }
  log.summary_dirty = false;
  log.summary_written = std::chrono::steady_clock::now();
}

}  // namespace mufric
