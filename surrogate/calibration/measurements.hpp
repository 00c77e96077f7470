#pragma once
// Measured friction for a calibration: the rows, their conditions (exact or with an uncertainty) and
// data sets, read from measurement CSV files.
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "common/input_space.hpp"
#include "surrogate/calibration/priors.hpp"

namespace mufric {

// Measured friction at n conditions, from one or several data sets (files).
struct Measurements {
  std::vector<std::string> condition_names;  // model inputs they fix, e.g. contact_pressure, sliding_velocity
  Eigen::MatrixXd conditions;                // n × c, SI: each condition's stated value (its mean or range's middle)
  // A condition known only within an uncertainty, per cell (SI): a normal's SD or a uniform range's
  // half-width, at most one of them positive; both 0 (or the matrices left empty): known exactly.
  Eigen::MatrixXd condition_sd, condition_half_width;
  Eigen::VectorXd mu;                        // measured μ
  Eigen::VectorXd mu_sd;                     // its standard deviation (the measurement's own scatter), > 0
  std::vector<std::string> row_names;        // for messages and provenance: "friction.csv line 4"
  // Each row's data set (an index into data_sets; empty: one set, "measurements").
  std::vector<std::string> data_sets;
  std::vector<int> data_set_of_row;

  Eigen::Index rows() const { return mu.size(); }
  bool uncertain(Eigen::Index row, Eigen::Index condition) const;
  // The prior of the true value of cell (row, condition): normal(stated, sd) or uniform(stated ± half-width).
  Prior condition_prior(Eigen::Index row, Eigen::Index condition) const;
};
// The same measurements with every optional part sized: uncertainty matrices of zeros, one data set.
Measurements completed(Measurements data);
// One data set after another (each file one set, named by the file's stem; equal names get a suffix).
// Every set must give the same conditions (in any column order): the error names the set and the
// condition it lacks.
Measurements combine_measurement_sets(const std::vector<Measurements>& sets);

// A measurement file: a CSV (common/csv_table.hpp) with a column per condition, named as the
// model's input with its unit ("contact_pressure[MPa],sliding_velocity[m/min],temperature[C]"), and
// "mu" and "mu_sd" (the measurement's standard deviation); '#' lines carry the provenance. A
// condition may come with its uncertainty: "temperature_sd[C]" (a normal SD; 0 in a row: known
// exactly) or "temperature_min[C]" and "temperature_max[C]" (a uniform range; the value column may
// then be left out). Rows are named "FILE line N"; the file is one data set, named by its stem.
// Errors name the file, line and column.
Measurements read_measurements(const std::string& path);

// The box a pair's campaign needs for these measurements: each condition over the rows (an uncertain
// one's value ± kBoxSds SDs, or its range), widened by `margin` of its width on each side, in
// log for the pressure and the velocity (positive, spanning decades), linearly for the temperature,
// which stays above kLowestBoxTemperature. In the order of condition_names. Throws Error for a
// negative margin or a condition that is not a model input.
inline constexpr double kBoxSds = 2.0;
inline constexpr double kLowestBoxTemperature = 250.0;  // K
InputSpace box_for_measurements(const Measurements& data, double margin);

}  // namespace mufric
