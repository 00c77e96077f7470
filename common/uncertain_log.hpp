#pragma once
// Where the meso code goes and the surrogate is unsure: query points whose 95 % interval is wider
// than a threshold, or that lie outside the model's box, appended per model to DIR/<model>.csv
// (unit header, SI values; renamed to <model>.csv.1 when full), the file `mufric dataset refine
// --candidates [--grow-box]` and `mufric learn` read; and
// per input and side, how many queries fell outside the box and how far, in DIR/<model>.outside.json.
// Opt-in: `serve --log-uncertain DIR` for a served model, or the client option `log_uncertain=DIR` for
// one evaluated in-process (the same files, so `learn` follows a meso code either way). It makes every
// logged call compute the predictive std, which a GP pays n²/2 multiply-adds per point for (and a
// clamped point the model at the real point outside the box, where no fast grid answers).
#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "common/input_space.hpp"

namespace mufric {

// Queries of one input outside the box: how many on each side, and the farthest seen (SI).
struct OutsideInputCount {
  long long below = 0, above = 0;
  double lowest = 0.0, highest = 0.0;  // meaningful only where below / above > 0
};

struct OutsideSummary {
  long long queries = 0;          // points with finite inputs asked of the model since its box was last set
                                  // (an invalid point gets a status and is not counted)
  long long outside_queries = 0;  // of those, points with at least one input outside the box
  std::vector<OutsideInputCount> inputs;  // the model's input order
};

class UncertainQueryLog {
 public:
  // Throws Error naming the directory if it cannot be created.
  UncertainQueryLog(std::string directory, double width_threshold, long long max_rows_per_model);
  // Writes every model's outside summary that changed since its last write.
  ~UncertainQueryLog();
  UncertainQueryLog(const UncertainQueryLog&) = delete;
  UncertainQueryLog& operator=(const UncertainQueryLog&) = delete;

  // Appends the points (rows of x, SI, the model's input order) whose interval width
  // 2 · 1.96 · std exceeds the threshold or that lie outside `inputs`' box (angles are periodic and
  // never outside). A model's file holds at most max_rows_per_model rows: the batch that would pass
  // it first renames the full file to NAME.csv.1 (replacing the one before) and begins a new one.
  void record(const std::string& model, const InputSpace& inputs, const Eigen::Ref<const Eigen::MatrixXd>& x,
              const Eigen::Ref<const Eigen::VectorXd>& std);
  long long rows(const std::string& model) const;  // in the model's current file
  OutsideSummary outside(const std::string& model) const;
  std::string path(const std::string& model) const;
  std::string rotated_path(const std::string& model) const;  // NAME.csv.1: the full log renamed
  std::string outside_path(const std::string& model) const;
  // Writes the summaries now (the destructor does; a summary is otherwise rewritten at most once a
  // second, so that a crash loses at most a second of counts and a busy server no file writes).
  void flush();

 private:
  struct ModelLog {
    long long rows = 0;          // in the model's current file
    bool rows_counted = false;   // rows read from a file an earlier process left
    OutsideSummary outside;
    InputSpace box;
    bool summary_dirty = false;
    std::chrono::steady_clock::time_point summary_written{};
  };
  void append_rows(const std::string& model, ModelLog& log, const InputSpace& inputs, const std::string& text, long long added);
  void write_summary(const std::string& model, ModelLog& log);

  std::string directory_;
  double width_threshold_;
  long long max_rows_;
  mutable std::mutex lock_;
  std::map<std::string, ModelLog> models_;
};

}  // namespace mufric
