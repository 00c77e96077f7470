#include "common/dataset_file.hpp"

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>


#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/isolation.hpp"
#include "common/version.hpp"

namespace mufric {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

Dataset read_hdf5_dataset(const std::string& path) {
  const h5::Reader in(path, "dataset");
  const long long version = in.require_format(kDatasetFormat, kOldestReadableDatasetSchema, kDatasetSchemaVersion, "mufric dataset");
  Dataset d;
  d.inputs = read_input_space(in);
  const auto dims = static_cast<Eigen::Index>(d.inputs.size());
  d.x = in.matrix("/samples/inputs");
  if (d.x.cols() != dims && d.x.rows() > 0) {
    in.fail("/samples/inputs", "has " + std::to_string(d.x.cols()) + " columns, " +
                                   std::to_string(dims) + " inputs are declared");
  }
  const Eigen::Index n = d.x.rows();
  d.mu = in.vector("/samples/mu", n);
  if (in.has("/samples/mu_std")) {
    d.mu_std = in.vector("/samples/mu_std", n);
    for (Eigen::Index i = 0; i < n; ++i) {
      if (d.mu_std(i) < 0.0) in.fail("/samples/mu_std", "row " + std::to_string(i) + " is negative");
    }
  } else {
    d.mu_std = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
    if (version < 2) {
      d.note = "schema version " + std::to_string(version) + ": no /samples/mu_std (each sample's standard error is "
               "unknown; a GP trained on it learns one noise level for all)";
    }
  }
  d.status = in.ints("/samples/status");
  if (static_cast<Eigen::Index>(d.status.size()) != n) in.fail("/samples/status", "length differs from /samples/inputs");
  for (size_t i = 0; i < d.status.size(); ++i) {
    if (d.status[i] < 0 || d.status[i] > static_cast<long long>(SampleStatus::outside_model)) {
      in.fail("/samples/status", "row " + std::to_string(i) + " is " + std::to_string(d.status[i]) +
                                     " (0 converged, 1 failed, 2 outside the model)");
    }
  }
  d.failure_reason = in.has("/samples/failure_reason") ? in.strings("/samples/failure_reason")
                                                       : std::vector<std::string>(static_cast<size_t>(n));
  if (static_cast<Eigen::Index>(d.failure_reason.size()) != n) {
    in.fail("/samples/failure_reason", "length differs from /samples/inputs");
  }
  if (in.has("/samples/diagnostics")) {
    H5::H5File file(path, H5F_ACC_RDONLY);
    H5::Group group = file.openGroup("/samples/diagnostics");
    for (hsize_t i = 0; i < group.getNumObjs(); ++i) {
      const std::string name = group.getObjnameByIdx(i);
      d.diagnostics[name] = in.vector("/samples/diagnostics/" + name, n);
    }
  }
  if (in.has("/plan/inputs")) d.plan = in.matrix("/plan/inputs");
  if (d.plan.rows() > 0 && d.plan.cols() != dims) {
    in.fail("/plan/inputs", "has " + std::to_string(d.plan.cols()) + " columns, " + std::to_string(dims) +
                                " inputs are declared");
  }
  if (in.has("/samples/plan_index")) {
    d.plan_index = in.ints("/samples/plan_index");
    if (static_cast<Eigen::Index>(d.plan_index.size()) != n) in.fail("/samples/plan_index", "length differs from /samples/inputs");
    for (size_t i = 0; i < d.plan_index.size(); ++i) {
      if (d.plan_index[i] < -1 || d.plan_index[i] >= d.plan.rows()) {
        in.fail("/samples/plan_index", "row " + std::to_string(i) + " points to plan row " + std::to_string(d.plan_index[i]) +
                                           " of " + std::to_string(d.plan.rows()));
      }
    }
  }
  if (in.has_attribute("/plan", "design")) d.plan_design = in.string_attribute("/plan", "design");
  if (in.has_attribute("/plan", "seed")) d.plan_seed = in.int_attribute("/plan", "seed");
  if (in.has_attribute("/plan", "draws")) d.draws = parse_draw_design(in.string_attribute("/plan", "draws"), path + ": /plan attribute draws");
  for (auto [name, seeds] : {std::pair{"/samples/tool_seed", &d.tool_seed}, std::pair{"/samples/chip_seed", &d.chip_seed}}) {
    if (!in.has(name)) continue;
    *seeds = in.ints(name);
    if (static_cast<Eigen::Index>(seeds->size()) != n) in.fail(name, "length differs from /samples/inputs");
  }
  if (in.has("/samples/draw_mu")) {
    d.draw_mu = in.matrix("/samples/draw_mu");
    if (d.draw_mu.rows() != n && d.draw_mu.cols() > 0) in.fail("/samples/draw_mu", "has " + std::to_string(d.draw_mu.rows()) + " rows, " + std::to_string(n) + " samples");
  }
  if (d.draw_mu.rows() != n) d.draw_mu.resize(n, 0);
  if (in.has("/plan/box_history")) d.box_history = in.strings("/plan/box_history");
  if (in.has_attribute("/", "source")) d.source = in.string_attribute("/", "source");
  if (in.has_attribute("/", "scene_json")) d.scene_json = in.string_attribute("/", "scene_json");
  if (in.has_attribute("/", "code_version")) d.code_version = in.string_attribute("/", "code_version");
  if (in.has_attribute("/", "created_utc")) d.created_utc = in.string_attribute("/", "created_utc");
  return d;
}

// CSV: every column but "mu" is an input, with its unit in the header; the box is the data's range.
Dataset read_csv_dataset(const std::string& path) {
  const CsvTable table = read_csv_table(path);
  table.column("mu");
  Dataset d;
  d.source = "csv:" + std::filesystem::path(path).filename().string();
  std::vector<std::vector<double>> columns;
  const std::vector<std::string>& known = known_input_names();
  for (const auto& c : table.columns) {
    if (c.name == "mu" || c.name == "mu_std") continue;
    // A column that is not a known input is a mistake, not a new input: an id column became a fourth
    // input, and 'pressure[MPa]' an input "pressure" in unit "1" (issue 30).
    if (std::find(known.begin(), known.end(), c.name) == known.end()) {
      std::string names;
      for (const auto& k : known) names += (names.empty() ? "" : ", ") + k;
      throw Error(path + ": column '" + c.name + "' is not a model input (inputs: " + names +
                  "; outputs: mu, mu_std); rename it, or remove it from the file");
    }
    columns.push_back(table.si_column(c.name));
    const QuantityKind kind = kind_of_input(c.name);
    for (size_t i = 0; i < columns.back().size(); ++i) {
      const std::string why = physical_range_violation(columns.back()[i], kind);
      if (!why.empty()) {
        throw Error(path + ": line " + std::to_string(table.line_of_row[i]) + ", column '" + c.name + "': " + why);
      }
    }
    d.inputs.push_back({c.name, std::string(si_unit(kind)), 0.0, 0.0});
  }
  if (d.inputs.empty()) throw Error(path + ": no input columns besides 'mu'");
  const auto n = static_cast<Eigen::Index>(table.rows.size());
  const auto dims = static_cast<Eigen::Index>(d.inputs.size());
  d.x.resize(n, dims);
  for (Eigen::Index j = 0; j < dims; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) d.x(i, j) = columns[static_cast<size_t>(j)][static_cast<size_t>(i)];
    if (n > 0) {
      d.inputs[static_cast<size_t>(j)].lo = d.x.col(j).minCoeff();
      d.inputs[static_cast<size_t>(j)].hi = d.x.col(j).maxCoeff();
    }
  }
  const auto mu = table.si_column("mu");
  d.mu = Eigen::Map<const Eigen::VectorXd>(mu.data(), n);
  d.mu_std = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  if (table.has_column("mu_std")) {
    const auto std_error = table.si_column("mu_std");
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!(std_error[static_cast<size_t>(i)] >= 0.0)) {
        throw Error(path + ": line " + std::to_string(table.line_of_row[static_cast<size_t>(i)]) +
                    ", column 'mu_std': a standard error must be a number >= 0");
      }
      d.mu_std(i) = std_error[static_cast<size_t>(i)];
    }
  }
  d.status.assign(static_cast<size_t>(n), static_cast<long long>(SampleStatus::converged));
  d.failure_reason.assign(static_cast<size_t>(n), "");
  d.plan = d.x;
  return d;
}

}  // namespace

const char* draw_design_name(DrawDesign d) {
  switch (d) {
    case DrawDesign::independent: return "independent";
    case DrawDesign::common: return "common";
    case DrawDesign::unknown: break;
  }
  return "";
}

DrawDesign parse_draw_design(const std::string& text, const std::string& field) {
  if (text == "independent") return DrawDesign::independent;
  if (text == "common") return DrawDesign::common;
  throw Error(field + ": '" + text + "' is not a draw design (independent or common)");
}

Dataset read_dataset(const std::string& path) {
  if (ends_with(path, ".csv")) return read_csv_dataset(path);
  try {
    return read_hdf5_dataset(path);
  } catch (const H5::Exception& e) {  // what the field-naming reads above do not translate themselves
    throw Error("dataset '" + path + "': unreadable HDF5 (" + e.getDetailMsg() + ")");
  }
}

Dataset read_dataset_isolated(const std::string& path, const IsolationLimits& limits) {
  if (ends_with(path, ".csv")) return read_csv_dataset(path);  // our own parser, no HDF5
  const IsolatedCopy copy = rewrite_in_child(path, "dataset", [](const std::string& original, const std::string& rewritten) {
    write_dataset(rewritten, read_dataset(original));
  }, limits);
  return read_dataset(copy.path());
}

void write_dataset(const std::string& path, const Dataset& d) {
  const auto n = d.x.rows();
  if (d.mu.size() != n || (d.mu_std.size() != 0 && d.mu_std.size() != n) || static_cast<Eigen::Index>(d.status.size()) != n ||
      static_cast<Eigen::Index>(d.failure_reason.size()) != n ||
      (!d.tool_seed.empty() && static_cast<Eigen::Index>(d.tool_seed.size()) != n) ||
      (!d.chip_seed.empty() && static_cast<Eigen::Index>(d.chip_seed.size()) != n) ||
      (d.draw_mu.cols() > 0 && d.draw_mu.rows() != n) ||
      (!d.plan_index.empty() && static_cast<Eigen::Index>(d.plan_index.size()) != n)) {
    throw Error("write_dataset '" + path + "': samples arrays differ in length");
  }
  h5::Writer out(path);
  out.string_attribute("/", "format", kDatasetFormat);
  out.int_attribute("/", "schema_version", kDatasetSchemaVersion);
  out.string_attribute("/", "code_version", d.code_version.empty() ? code_version() : d.code_version);
  out.string_attribute("/", "created_utc", d.created_utc.empty() ? utc_timestamp() : d.created_utc);
  out.string_attribute("/", "source", d.source);
  out.string_attribute("/", "scene_json", d.scene_json);
  out.string_attribute("/", "scene_sha256", sha256_hex(d.scene_json));
  write_input_space(out, d.inputs);
  out.group("/samples");
  out.matrix("/samples/inputs", d.x);
  out.doubles("/samples/mu", d.mu);
  out.doubles("/samples/mu_std", d.mu_std.size() == n ? d.mu_std : Eigen::VectorXd(Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN())));
  out.ints("/samples/status", d.status);
  out.strings("/samples/failure_reason", d.failure_reason);
  out.group("/samples/diagnostics");
  for (const auto& [name, values] : d.diagnostics) out.doubles("/samples/diagnostics/" + name, values);
  if (!d.plan_index.empty()) out.ints("/samples/plan_index", d.plan_index);
  if (!d.tool_seed.empty()) out.ints("/samples/tool_seed", d.tool_seed);
  if (!d.chip_seed.empty()) out.ints("/samples/chip_seed", d.chip_seed);
  if (d.draw_mu.cols() > 0) out.matrix("/samples/draw_mu", d.draw_mu);
  out.group("/plan");
  out.matrix("/plan/inputs", d.plan);
  if (!d.plan_design.empty()) {
    out.string_attribute("/plan", "design", d.plan_design);
    out.int_attribute("/plan", "seed", d.plan_seed);
  }
  if (d.draws != DrawDesign::unknown) out.string_attribute("/plan", "draws", draw_design_name(d.draws));
  if (!d.box_history.empty()) out.strings("/plan/box_history", d.box_history);
  out.commit();
}

TrainingSet training_set(const Dataset& d, const std::string& path) {
  TrainingSet t;
  t.inputs = d.inputs;
  t.source_path = path;
  t.source_hash = sha256_file(path);
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    t.outside_model += d.outside_model(i);
    if (!d.converged(i)) continue;
    for (Eigen::Index j = 0; j < d.x.cols(); ++j) {
      if (!std::isfinite(d.x(i, j))) {
        throw Error(path + ": sample row " + std::to_string(i) + ", input '" + d.inputs[static_cast<size_t>(j)].name +
                    "' is not finite (" + std::to_string(d.x(i, j)) + ")");
      }
    }
    if (!std::isfinite(d.mu(i))) {
      throw Error(path + ": sample row " + std::to_string(i) + ", mu is not finite but the sample is marked converged");
    }
    rows.push_back(i);
  }
  if (rows.empty()) throw Error(path + ": no converged samples to train on");
  t.x.resize(static_cast<Eigen::Index>(rows.size()), d.x.cols());
  t.mu.resize(static_cast<Eigen::Index>(rows.size()));
  t.mu_std.resize(static_cast<Eigen::Index>(rows.size()));
  t.draws = d.draws;
  const bool with_draws = d.draw_mu.cols() > 0 && d.draw_mu.rows() == d.size();
  t.draw_mu.resize(static_cast<Eigen::Index>(rows.size()), with_draws ? d.draw_mu.cols() : 0);
  for (size_t k = 0; k < rows.size(); ++k) {
    if (with_draws) t.draw_mu.row(static_cast<Eigen::Index>(k)) = d.draw_mu.row(rows[k]);
    t.x.row(static_cast<Eigen::Index>(k)) = d.x.row(rows[k]);
    t.mu(static_cast<Eigen::Index>(k)) = d.mu(rows[k]);
    t.mu_std(static_cast<Eigen::Index>(k)) = d.mu_std.size() == d.size() ? d.mu_std(rows[k]) : std::numeric_limits<double>::quiet_NaN();
  }
  return t;
}

}  // namespace mufric
