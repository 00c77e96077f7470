#pragma once
// Where the meso code goes and the surrogate is unsure: query points whose 95 % interval is wider
// than a threshold, appended per model to DIR/<model>.csv (unit header, SI values), the file
// `mufric dataset refine --candidates` reads. Opt-in (`serve --log-uncertain DIR`): it makes every
// call compute the predictive std, which a GP pays n²/2 multiply-adds per point for.
#include <map>
#include <mutex>
#include <string>

#include <Eigen/Dense>

#include "common/input_space.hpp"

namespace mufric::server {

class UncertainQueryLog {
 public:
  // Throws Error naming --log-uncertain if the directory cannot be created.
  UncertainQueryLog(std::string directory, double width_threshold, long long max_rows_per_model);

  // Appends the points (rows of x, SI, the model's input order) whose interval width
  // 2 · 1.96 · std exceeds the threshold; stops for a model after max_rows_per_model rows.
  void record(const std::string& model, const InputSpace& inputs, const Eigen::Ref<const Eigen::MatrixXd>& x,
              const Eigen::Ref<const Eigen::VectorXd>& std);
  long long rows(const std::string& model) const;
  std::string path(const std::string& model) const;

 private:
  std::string directory_;
  double width_threshold_;
  long long max_rows_;
  mutable std::mutex lock_;
  std::map<std::string, long long> rows_;
};

}  // namespace mufric::server
