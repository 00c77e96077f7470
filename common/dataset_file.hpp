#pragma once
// The training database (docs/formats.md, "The dataset file"): one HDF5 file, SI units, self-describing.
//   /samples/inputs n×d, /samples/mu n, /samples/mu_std n (μ's standard error over tool phases and
//   realisations; NaN where not known), /samples/status n (0 converged, 1 failed, 2 outside the
//   model: completed, but e.g. molten), /samples/failure_reason n (why failed / outside the model),
//   /samples/diagnostics/<name> n (optional), /plan/inputs m×d;
//   /samples/plan_index n (optional: the plan row each sample answers, −1 for none), /plan
//   attributes design and seed (optional), draws ("independent": every plan row its own roughness
//   draws, "common": every row the scene's; optional), /samples/tool_seed and /samples/chip_seed n
//   (the row's base seeds, −1: the scene's own; optional), /samples/draw_mu n×D (each draw's μ, NaN
//   padded; optional);
//   root attributes: format, schema_version, input_names/units (in /inputs), box, provenance.
// A CSV with unit-annotated header ("contact_pressure[MPa],...,mu") is accepted for training too.
#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "common/h5_file.hpp"
#include "common/isolation.hpp"
#include "common/input_space.hpp"

namespace mufric {

// Version 2 added /samples/mu_std and status 2; version-1 files are still read (μ's standard error
// unknown: NaN, and Dataset::note says so). Version 3 added the draws' design (/plan attribute
// draws), each sample's seeds (/samples/tool_seed, /samples/chip_seed) and each draw's μ
// (/samples/draw_mu); older files read as common draws with unknown per-draw μ.
inline constexpr long long kDatasetSchemaVersion = 3;
inline constexpr long long kOldestReadableDatasetSchema = 1;
inline constexpr const char* kDatasetFormat = "mufric-dataset";

enum class SampleStatus : long long { converged = 0, failed = 1, outside_model = 2 };

// How a plan's rows draw their roughness (issue 33). Independent: each row its own tools and chip
// surfaces, so that their error is independent between samples and averages out over a campaign
// (stochastic kriging; Ankenman, Nelson & Staum 2010). Common: every row the scene's own surfaces
// (common random numbers: good for trends and differences, but their shared error never averages
// out; Chen, Ankenman & Nelson 2012). Unknown: a file from before the choice existed (common).
enum class DrawDesign { unknown, independent, common };
const char* draw_design_name(DrawDesign d);  // "", "independent", "common"
DrawDesign parse_draw_design(const std::string& text, const std::string& field);

struct Dataset {
  InputSpace inputs;                // names, SI units, box
  h5::RowMatrix x;                  // n × d, SI
  Eigen::VectorXd mu;               // n (NaN allowed only for failed samples)
  Eigen::VectorXd mu_std;           // n, μ's standard error; NaN where not known
  std::vector<long long> status;    // n, SampleStatus
  std::vector<std::string> failure_reason;  // n, empty when converged
  std::map<std::string, Eigen::VectorXd> diagnostics;  // each n
  h5::RowMatrix plan;               // m × d requested points
  std::vector<long long> plan_index;  // n, row of `plan` each sample answers (−1: none); empty: unknown
  std::string plan_design;          // how the plan was drawn ("sobol", ...), empty if unknown
  long long plan_seed = 0;
  DrawDesign draws = DrawDesign::unknown;
  std::vector<long long> tool_seed, chip_seed;  // n each, the row's base seeds (−1: the scene's); empty: unknown
  h5::RowMatrix draw_mu;            // n × D, each draw's μ (NaN padded); 0 columns: unknown
  std::vector<std::string> box_history;  // one line per change of the box (dataset refine --grow-box)
  std::string source;               // how the samples were made (scene hash, law name, ...)
  std::string scene_json;           // scene text when made by the micro-model
  std::string code_version;
  std::string created_utc;
  std::string note;                 // what a reader should know about an older file (empty: nothing)

  Eigen::Index size() const { return x.rows(); }
  // Trained on: completed and inside the model.
  bool converged(Eigen::Index i) const { return status[static_cast<size_t>(i)] == static_cast<long long>(SampleStatus::converged); }
  bool failed(Eigen::Index i) const { return status[static_cast<size_t>(i)] == static_cast<long long>(SampleStatus::failed); }
  bool outside_model(Eigen::Index i) const {
    return status[static_cast<size_t>(i)] == static_cast<long long>(SampleStatus::outside_model);
  }
};

// Samples that converged, validated: finite inputs and μ. Errors name file, row and input.
struct TrainingSet {
  InputSpace inputs;
  Eigen::MatrixXd x;   // n × d, SI
  Eigen::VectorXd mu;  // n
  Eigen::VectorXd mu_std;  // n, μ's standard error; NaN where not known
  DrawDesign draws = DrawDesign::unknown;  // the dataset's
  Eigen::MatrixXd draw_mu;  // n × D, each draw's μ (NaN padded); 0 columns: not known
  long long outside_model = 0;  // samples left out because they lie outside the model (molten)
  std::string source_path;
  std::string source_hash;  // SHA-256 of the file bytes, for model provenance
  std::string description;  // how the samples were made (campaign_summary), kept in a model's provenance
};

// Reads .h5 (dataset schema) or .csv; throws Error naming the file and the problem.
Dataset read_dataset(const std::string& path);
// read_dataset for a file that may be corrupt: an HDF5 file is parsed in a child process and read
// back from the copy it wrote (common/isolation.hpp), so a crash of the HDF5 library is an Error.
Dataset read_dataset_isolated(const std::string& path, const IsolationLimits& limits = {});
void write_dataset(const std::string& path, const Dataset& dataset);
TrainingSet training_set(const Dataset& dataset, const std::string& path);

}  // namespace mufric
