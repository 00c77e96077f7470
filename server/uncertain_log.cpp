#include "server/uncertain_log.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/error.hpp"

namespace mufric::server {
namespace {
constexpr double kZ95 = 1.959963984540054;  // two-sided 95 % normal quantile
}

UncertainQueryLog::UncertainQueryLog(std::string directory, double width_threshold, long long max_rows_per_model)
    : directory_(std::move(directory)), width_threshold_(width_threshold), max_rows_(max_rows_per_model) {
  if (!(width_threshold_ > 0.0)) throw Error("--uncertain-width must be positive");
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);
  if (ec) throw Error("--log-uncertain: cannot create '" + directory_ + "': " + ec.message());
}

std::string UncertainQueryLog::path(const std::string& model) const { return directory_ + "/" + model + ".csv"; }

long long UncertainQueryLog::rows(const std::string& model) const {
  std::lock_guard<std::mutex> guard(lock_);
  const auto it = rows_.find(model);
  return it == rows_.end() ? 0 : it->second;
}

void UncertainQueryLog::record(const std::string& model, const InputSpace& inputs,
                               const Eigen::Ref<const Eigen::MatrixXd>& x, const Eigen::Ref<const Eigen::VectorXd>& std) {
  std::string text;
  long long added = 0;
  std::lock_guard<std::mutex> guard(lock_);
  long long& written = rows_[model];
  for (Eigen::Index i = 0; i < x.rows() && written + added < max_rows_; ++i) {
    const double width = 2.0 * kZ95 * std(i);
    if (!(width > width_threshold_) || !x.row(i).allFinite()) continue;
    char cell[40];
    for (Eigen::Index j = 0; j < x.cols(); ++j) {
      std::snprintf(cell, sizeof cell, "%s%.17g", j ? "," : "", x(i, j));
      text += cell;
    }
    std::snprintf(cell, sizeof cell, ",%.6g\n", width);
    text += cell;
    ++added;
  }
  if (added == 0) return;
  const std::string file = path(model);
  const bool fresh = !std::filesystem::exists(file) || std::filesystem::file_size(file) == 0;
  if (fresh) {
    std::string header;
    for (size_t j = 0; j < inputs.size(); ++j) header += (j ? "," : "") + inputs[j].name + "[" + inputs[j].unit + "]";
    text = header + ",ci95_width\n" + text;
  }
  std::ofstream out(file, std::ios::app | std::ios::binary);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));  // one write per batch
  out.flush();
  if (!out) {
    std::fprintf(stderr, "mufric serve: cannot append to %s; uncertain queries of %s are not logged\n", file.c_str(),
                 model.c_str());
    written = max_rows_;
    return;
  }
  written += added;
  if (written >= max_rows_) {
    std::fprintf(stderr, "mufric serve: %s reached %lld logged uncertain queries; logging for %s stops\n", file.c_str(),
                 max_rows_, model.c_str());
  }
}

}  // namespace mufric::server
