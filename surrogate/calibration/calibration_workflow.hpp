#pragma once
// The calibration workflow as a library (what `mufric calibrate` does, front ends only parse options):
// read and check the measurements, decide which model inputs are the measurements' conditions and
// which are the law's coefficients (the input table knows: a condition is on the wire, a coefficient
// is not), hold what the user fixes, build the problem with its priors, and, after sampling, the
// calibrated model from the posterior. Every check names the real cause: a condition the data do not
// give, a value that cannot be friction, a prior mostly outside the box, a model with nothing to
// calibrate.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "surrogate/calibration/calibrated_model.hpp"
#include "surrogate/calibration/calibration.hpp"
#include "surrogate/gp/gaussian_process.hpp"

namespace mufric {

// What a user asks of a calibration, in the words of the command line.
struct CalibrationRequest {
  std::vector<std::string> data_files;   // one data set each (a CSV, read_measurements)
  std::vector<std::string> fixed;        // "NAME=VALUE" with its unit, e.g. "adhesive_coefficient=0.35"
  std::vector<std::string> calibrated;   // law coefficients to calibrate; empty: every one not fixed
  std::string priors_file;               // JSON (parse_calibration_priors); empty: the defaults
  bool discrepancy = false;              // δ on, whatever the priors file says
  std::optional<double> discrepancy_trend_sd;  // δ's linear trend (CalibrationPriors), over the priors file's
};

struct CalibrationSetup {
  std::shared_ptr<const CalibrationProblem> problem;
  // What is suspicious but allowed, each one line naming the row, input or file (the caller prints them).
  std::vector<std::string> warnings;
  // The measurement files as given, with their '#' provenance lines, for the calibrated model's record.
  std::string data_source;
};

// μ values a measurement may not have: friction is not negative, and no sliding contact of a
// machining pair has μ of 10 (values like it are percentages or forces in the wrong column).
inline constexpr double kLargestPlausibleFriction = 10.0;
// A measurement farther than this many of its SDs outside every μ the campaign computed cannot be
// reached by any coefficient in the box: refused. Between 2 and this: a warning.
inline constexpr double kUnreachableMeasurementSds = 5.0;
inline constexpr double kSuspiciousMeasurementSds = 2.0;
// A prior (a coefficient's or an uncertain condition's) with less of its mass inside the model's box
// than this is mostly cut away: a warning (the posterior piles at the box's edge).
inline constexpr double kLeastPriorMassInsideBox = 0.5;

// With the discrepancy on, δ (a zero-mean GP of sampled amplitude) can explain this few measurements
// by itself: what the posterior then says of the coefficients comes from δ's amplitude prior, a warning.
inline constexpr long long kRowsTheDiscrepancyExplainsAlone = 2;

// Reads, checks and sets up a calibration of `emulator` (a campaign's GP). Throws Error naming the
// cause (file, line, column, input) for what cannot be calibrated.
CalibrationSetup prepare_calibration(std::shared_ptr<const GaussianProcess> emulator, const CalibrationRequest& request);

// A calibrated model's calibration set up again on another emulator (its campaign's GP retrained):
// the same measurements, calibrated and held inputs, priors and data source. Throws Error when the
// model's file predates kept priors, or the emulator's inputs are not its emulator's (names and order).
CalibrationSetup recalibration_setup(const CalibratedModel& model, std::shared_ptr<const GaussianProcess> emulator);

// The record a calibrated model keeps of its calibration.
CalibrationRecord calibration_record(const CalibrationSetup& setup, const CalibrationResult& result);

// The calibrated model of a finished calibration (its samples thinned to CalibratedPosterior's default).
CalibratedModel calibrated_model(const CalibrationSetup& setup, const CalibrationResult& result);

// The most steps a calibration not yet within the limits runs to, its length doubling (calibrate's
// --max-steps default, and a recalibration's).
inline constexpr int kDefaultCalibrationMaxSteps = 40000;

}  // namespace mufric
