#pragma once
// The training database (ARCHITECTURE.md "Dataset"): one HDF5 file, SI units, self-describing.
//   /samples/inputs n×d, /samples/mu n, /samples/status n (0 converged, 1 failed),
//   /samples/failure_reason n, /samples/diagnostics/<name> n (optional), /plan/inputs m×d;
//   /samples/plan_index n (optional: the plan row each sample answers, −1 for none), /plan
//   attributes design and seed (optional);
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

inline constexpr long long kDatasetSchemaVersion = 1;
inline constexpr const char* kDatasetFormat = "mufric-dataset";

enum class SampleStatus : long long { converged = 0, failed = 1 };

struct Dataset {
  InputSpace inputs;                // names, SI units, box
  h5::RowMatrix x;                  // n × d, SI
  Eigen::VectorXd mu;               // n (NaN allowed only for failed samples)
  std::vector<long long> status;    // n, SampleStatus
  std::vector<std::string> failure_reason;  // n, empty when converged
  std::map<std::string, Eigen::VectorXd> diagnostics;  // each n
  h5::RowMatrix plan;               // m × d requested points
  std::vector<long long> plan_index;  // n, row of `plan` each sample answers (−1: none); empty: unknown
  std::string plan_design;          // how the plan was drawn ("sobol", ...), empty if unknown
  long long plan_seed = 0;
  std::string source;               // how the samples were made (scene hash, law name, ...)
  std::string scene_json;           // scene text when made by the micro-model
  std::string code_version;
  std::string created_utc;

  Eigen::Index size() const { return x.rows(); }
  bool converged(Eigen::Index i) const { return status[static_cast<size_t>(i)] == static_cast<long long>(SampleStatus::converged); }
};

// Samples that converged, validated: finite inputs and μ. Errors name file, row and input.
struct TrainingSet {
  InputSpace inputs;
  Eigen::MatrixXd x;   // n × d, SI
  Eigen::VectorXd mu;  // n
  std::string source_path;
  std::string source_hash;  // SHA-256 of the file bytes, for model provenance
};

// Reads .h5 (dataset schema) or .csv; throws Error naming the file and the problem.
Dataset read_dataset(const std::string& path);
// read_dataset for a file that may be corrupt: an HDF5 file is parsed in a child process and read
// back from the copy it wrote (common/isolation.hpp), so a crash of the HDF5 library is an Error.
Dataset read_dataset_isolated(const std::string& path, const IsolationLimits& limits = {});
void write_dataset(const std::string& path, const Dataset& dataset);
TrainingSet training_set(const Dataset& dataset, const std::string& path);

// Hex SHA-256 (OpenSSL) of a file's bytes.
std::string sha256_file(const std::string& path);
std::string sha256_hex(const std::string& bytes);

}  // namespace mufric
