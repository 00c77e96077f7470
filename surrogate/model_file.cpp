#include "surrogate/model_file.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>

#include <omp.h>

#include "common/dataset_file.hpp"
#include "common/error.hpp"
#include "common/isolation.hpp"
#include "common/version.hpp"
#include "surrogate/calibrated_model.hpp"
#include "surrogate/cholesky.hpp"
#include "surrogate/empirical_laws.hpp"
#include "surrogate/fast_evaluator.hpp"
#include "surrogate/gaussian_process.hpp"
#include "surrogate/gp_training.hpp"

namespace mufric {
namespace {

// A loaded GP must satisfy K α = y to this normwise backward error; a backward-stable solve gives
// about n·ε, a flipped bit in α, L or x_train gives O(1). Lenient when α is large (ill-conditioned K),
// hence the entry-wise factor check below when the factor is stored.
constexpr double kLoadBackwardErrorTolerance = 1e-8;
// Entries of L Lᵀ must match the kernel rebuilt from x_train and the hyper-parameters to this
// fraction of the diagonal; roundoff of a Cholesky factorisation is about n·ε.
constexpr double kFactorEntryTolerance = 1e-8;
// α recomputed from the stored factor must match the stored α this closely (same algorithm).
constexpr double kAlphaRecomputeTolerance = 1e-10;

// Compares (L Lᵀ)ᵢⱼ with Kᵢⱼ on the sub-diagonal and three full columns: O(n²), and any change of
// a hyper-parameter or a training input moves some of these entries.
bool factor_matches_kernel(const Eigen::MatrixXd& l, const Eigen::MatrixXd& kf, double diagonal) {
  const Eigen::Index n = l.rows();
  const double tolerance = kFactorEntryTolerance * (kf(0, 0) + diagonal);
  auto entry_ok = [&](Eigen::Index i, Eigen::Index j) {  // i ≥ j
    const double llt = l.row(i).head(j + 1).dot(l.row(j).head(j + 1));
    const double k = kf(i, j) + (i == j ? diagonal : 0.0);
    return std::abs(llt - k) <= tolerance;
  };
  for (Eigen::Index i = 1; i < n; ++i) {
    if (!entry_ok(i, i - 1)) return false;
  }
  for (const Eigen::Index j : {Eigen::Index{0}, n / 2, n - 1}) {
    for (Eigen::Index i = j; i < n; ++i) {
      if (!entry_ok(i, j)) return false;
    }
  }
  return true;
}

// The fields of /gp/training, written and read from the same tables so the two cannot drift apart.
constexpr std::pair<const char*, double GpTrainingSummary::*> kSummaryNumbers[] = {
    {"log_marginal_likelihood", &GpTrainingSummary::log_marginal_likelihood},
    {"loo_mean_relative_error", &GpTrainingSummary::loo_mean_relative_error},
    {"loo_max_relative_error", &GpTrainingSummary::loo_max_relative_error},
    {"loo_rmse", &GpTrainingSummary::loo_rmse},
    {"loo_coverage_95", &GpTrainingSummary::loo_coverage_95},
    {"seconds", &GpTrainingSummary::seconds}};
constexpr std::pair<const char*, long long GpTrainingSummary::*> kSummaryCounts[] = {
    {"starts", &GpTrainingSummary::starts}, {"best_start", &GpTrainingSummary::best_start}};
constexpr std::pair<const char*, std::string GpTrainingSummary::*> kSummaryTexts[] = {
    {"dataset_path", &GpTrainingSummary::dataset_path},
    {"dataset_sha256", &GpTrainingSummary::dataset_sha256},
    {"code_version", &GpTrainingSummary::code_version},
    {"created_utc", &GpTrainingSummary::created_utc}};
// Written by every model since it was kept; a file from before has none (read as "").
constexpr const char* kSummaryDatasetDescription = "dataset_description";
// Likewise; a file from before has none, and it is recomputed at load up to this many training points
// (the LOO needs K⁻¹: n³/3, ~0.05 s at 1000).
constexpr const char* kSummaryStandardisedRms = "loo_standardised_rms";
constexpr Eigen::Index kMostPointsForLooAtLoad = 1000;
// Nodes of a stored fast evaluator recomputed with the exact model at load. A node is the exact
// model's value, but computed in another batch: near the noise floor σ is the square root of a
// difference of nearly equal numbers, and two evaluation paths differ there far beyond 1e-9 (issue
// 30: a model `train` wrote was refused). A node must match to within the file's own certified bound
// (the accuracy every request that uses the grid relies on), or this rounding floor where the bound is
// smaller still; a grid of another model or altered values misses by more.
constexpr long long kFastSpotChecks = 64;
constexpr double kFastNodeRoundingFloor = 1e-9;

// What the stored checksum covers: the grid's shape, its node values' bytes and the bounds.
// A std floor of 0 (files before it) adds nothing, so that their checksums still match.
std::string fast_evaluator_digest(const std::vector<long long>& cells, const std::vector<double>& values,
                                  const FastEvaluatorBounds& bounds) {
  std::string bytes;
  for (const long long c : cells) bytes += std::to_string(c) + ",";
  char text[96];
  std::snprintf(text, sizeof text, "%.17g,%.17g,", bounds.mu_absolute, bounds.std_relative);
  bytes += text;
  if (bounds.std_floor != 0.0) {
    std::snprintf(text, sizeof text, "floor %.17g,", bounds.std_floor);
    bytes += text;
  }
  bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  return sha256_hex(bytes);
}

std::vector<double> column(const std::vector<MlrRow>& rows, double MlrRow::*field) {
  std::vector<double> values;
  for (const auto& r : rows) values.push_back(r.*field);
  return values;
}

}  // namespace

void save_model(const std::string& path, const FrictionModel& model) {
  h5::Writer out(path);
  out.string_attribute("/", "format", kModelFormat);
  out.int_attribute("/", "schema_version", kModelSchemaVersion);
  out.string_attribute("/", "kind", std::string(model.kind()));
  out.string_attribute("/", "code_version", code_version());
  out.string_attribute("/", "created_utc", utc_timestamp());
  write_input_space(out, model.inputs());
  out.string_attribute("/", "extrapolation", std::string(to_string(model.default_extrapolation())));
  out.double_attribute("/", "mu_min", model.mu_min());
  out.double_attribute("/", "mu_max", model.mu_max());
  model.write(out);
  out.commit();
}

namespace {
// The policy for points outside the box and μ's physical range (files before them: the defaults).
void read_extrapolation(const h5::Reader& in, FrictionModel& model) {
  if (in.has_attribute("/", "extrapolation")) {
    try {
      model.set_default_extrapolation(extrapolation_from_string(in.string_attribute("/", "extrapolation")));
    } catch (const Error& e) {
      in.fail("/", std::string("attribute extrapolation: ") + e.what());
    }
  }
  if (in.has_attribute("/", "mu_min") || in.has_attribute("/", "mu_max")) {
    try {
      model.set_mu_range(in.double_attribute("/", "mu_min"), in.double_attribute("/", "mu_max"));
    } catch (const Error& e) {
      in.fail("/", std::string("attributes mu_min, mu_max: ") + e.what());
    }
  }
}

std::unique_ptr<FrictionModel> read_kind(const h5::Reader& in, const std::string& kind, InputSpace inputs) {
  if (kind == "gp") return std::make_unique<GaussianProcess>(GaussianProcess::read(in, std::move(inputs)));
  if (kind == "mlr") return std::make_unique<MlrLaw>(MlrLaw::read(in, std::move(inputs)));
  if (kind == "coulomb") return std::make_unique<CoulombLaw>(CoulombLaw::read(in, std::move(inputs)));
  if (kind == "calibrated") return std::make_unique<CalibratedModel>(CalibratedModel::read(in, std::move(inputs)));
  return nullptr;
}

std::unique_ptr<FrictionModel> read_model(const std::string& path) {
  const h5::Reader in(path, "model");
  in.require_format(kModelFormat, kOldestReadableModelSchema, kModelSchemaVersion, "mufric model");
  InputSpace inputs = read_input_space(in);
  const std::string kind = in.string_attribute("/", "kind");
  try {
    if (auto model = read_kind(in, kind, std::move(inputs))) {
      read_extrapolation(in, *model);
      return model;
    }
  } catch (const H5::Exception& e) {
    in.fail("/" + kind, "unreadable (" + e.getDetailMsg() + ")");
  } catch (const Error& e) {
    const std::string message = e.what();
    if (message.rfind("model '", 0) == 0) throw;
    in.fail("/" + kind, message);
  }
  in.fail("/", "unknown model kind '" + kind + "' (known: gp, mlr, coulomb, calibrated)");
}
}  // namespace

std::unique_ptr<FrictionModel> load_model(const std::string& path) {
  try {
    return read_model(path);
  } catch (const H5::Exception& e) {  // what the field-naming reads do not translate themselves
    throw Error("model '" + path + "': unreadable HDF5 (" + e.getDetailMsg() + ")");
  }
}

std::unique_ptr<FrictionModel> load_model_isolated(const std::string& path, const IsolationLimits& limits) {
  const IsolatedCopy copy = rewrite_in_child(path, "model", [](const std::string& original, const std::string& rewritten) {
    // The child of a threaded parent runs on one thread: an OpenMP team there would wait for the
    // parent's pool threads, which fork() does not copy (libgomp is not fork-safe), so a model kind
    // that evaluates while it loads (a calibrated model's likelihood factors) would stall.
    omp_set_num_threads(1);
    save_model(rewritten, *load_model(original));
  }, limits);
  return load_model(copy.path());
}

namespace {

// The file this code was loaded from: libmufric.so for a meso code linked with -lmufric, else the
// executable it is linked into statically (dladdr of a function of this library).
std::filesystem::path file_holding_this_code() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&shipped_models_directory), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ignored;
  const std::filesystem::path path = std::filesystem::canonical(info.dli_fname, ignored);
  return ignored ? std::filesystem::path(info.dli_fname) : path;
}

// <prefix>/share/mufric/models for a file in <prefix>/bin, <prefix>/lib or <prefix>/lib/<multiarch>.
std::string models_beside(const std::filesystem::path& file) {
  std::error_code ignored;
  std::filesystem::path dir = file.parent_path();
  for (int up = 0; up < 2 && !dir.empty(); ++up, dir = dir.parent_path()) {
    const auto candidate = dir.parent_path() / "share/mufric/models";
    if (std::filesystem::is_directory(candidate, ignored)) return candidate.string();
  }
  return {};
}

bool is_inside(const std::filesystem::path& file, const std::filesystem::path& dir) {
  const auto relative = file.lexically_relative(dir);
  return !relative.empty() && *relative.begin() != "..";
}

}  // namespace

std::string shipped_models_directory() {
  namespace fs = std::filesystem;
  if (const char* set = std::getenv("MUFRIC_MODELS_DIR"); set != nullptr && *set != '\0') return set;
  std::error_code ignored;
  // From where this code lives, not from the calling executable: a meso code linked against an
  // installed libmufric.so finds <its prefix>/share/mufric/models wherever the meso code itself is
  // (issue 49: it found the build's source tree instead). Then the prefix configured at build time;
  // the source tree only for code running from its own build tree, so that an installed copy never
  // reads models from a source tree that may be gone or newer.
  const fs::path holder = file_holding_this_code();
  if (!holder.empty()) {
    if (std::string beside = models_beside(holder); !beside.empty()) return beside;
  }
  if (fs::is_directory(MUFRIC_INSTALLED_MODELS_DIR, ignored)) return MUFRIC_INSTALLED_MODELS_DIR;
  if ((holder.empty() || is_inside(holder, MUFRIC_BUILD_DIR)) && fs::is_directory(MUFRIC_SOURCE_MODELS_DIR, ignored)) {
    return MUFRIC_SOURCE_MODELS_DIR;
  }
  return {};
}

std::vector<std::string> shipped_model_names() {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  const std::string dir = shipped_models_directory();
  std::error_code error;
  if (dir.empty() || !fs::is_directory(dir, error)) return names;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.path().extension() == ".h5") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

namespace {

// A bare name (no '/'): the shipped model of that name, if there is one. Without ".h5" the shipped
// model wins over anything of that name here (a folder or file named dry_default in the working
// directory shadowed it with "not an HDF5 file"; a local file is ./dry_default); with ".h5" a
// regular file here comes first.
std::string shipped_model_path(const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ignored;
  if (name.empty() || name.find('/') != std::string::npos) return name;
  const bool has_extension = name.ends_with(".h5");
  if (has_extension && fs::is_regular_file(name, ignored)) return name;
  if (!has_extension && fs::exists(name, ignored)) {
    const std::string dir = shipped_models_directory();
    const bool shipped = !dir.empty() && fs::is_regular_file(fs::path(dir) / (name + ".h5"), ignored);
    if (!shipped) return name;
  }
  const std::string stem = has_extension ? name.substr(0, name.size() - 3) : name;
  const std::string dir = shipped_models_directory();
  if (const fs::path shipped = fs::path(dir) / (stem + ".h5"); !dir.empty() && fs::is_regular_file(shipped, ignored)) {
    return shipped.string();
  }
  if (has_extension) return name;  // a file name: opening it says it is missing
  std::string shipped;
  for (const auto& n : shipped_model_names()) shipped += (shipped.empty() ? "" : ", ") + n;
  throw Error("model '" + name + "': no such file here, and no shipped model of that name (" +
              (dir.empty() ? std::string("no shipped models found; set MUFRIC_MODELS_DIR")
                           : "shipped, in " + dir + ": " + (shipped.empty() ? std::string("none") : shipped)) +
              ")");
}

}  // namespace

std::string model_path_from_uri(const std::string& uri) {
  const std::string file_scheme = "file://";
  if (uri.rfind(file_scheme, 0) == 0) return shipped_model_path(uri.substr(file_scheme.size()));
  const auto scheme_end = uri.find("://");
  if (scheme_end != std::string::npos) {
    throw Error("model URI '" + uri + "': scheme '" + uri.substr(0, scheme_end) +
                "' is not handled here; use file:///path/model.h5, a plain path or a shipped model's name");
  }
  return shipped_model_path(uri);
}

// ---- Coulomb -------------------------------------------------------------------------------
void CoulombLaw::write(h5::Writer& out) const {
  out.group("/coulomb");
  out.double_attribute("/coulomb", "mu", mu_);
}

CoulombLaw CoulombLaw::read(const h5::Reader& in, InputSpace inputs) {
  return CoulombLaw(in.double_attribute("/coulomb", "mu"), std::move(inputs));
}

// ---- MLR -----------------------------------------------------------------------------------
void MlrLaw::write(h5::Writer& out) const {
  out.group("/mlr");
  out.string_attribute("/mlr", "source", source_);
  out.string_attribute("/mlr", "units", "mu = beta0 + beta1*v[m/min] + beta2*p[MPa]; angles in degrees");
  out.doubles("/mlr/fibre_angle_deg", column(rows_, &MlrRow::fibre_angle_deg));
  out.doubles("/mlr/beta0", column(rows_, &MlrRow::beta0));
  out.doubles("/mlr/beta1_per_m_min", column(rows_, &MlrRow::beta1_per_m_min));
  out.doubles("/mlr/beta2_per_mpa", column(rows_, &MlrRow::beta2_per_mpa));
  out.doubles("/mlr/mu_min", column(rows_, &MlrRow::mu_min));
  out.doubles("/mlr/mu_max", column(rows_, &MlrRow::mu_max));
  out.doubles("/mlr/r_squared", column(rows_, &MlrRow::r_squared));
}

MlrLaw MlrLaw::read(const h5::Reader& in, InputSpace inputs) {
  const auto angles = in.doubles("/mlr/fibre_angle_deg");
  const auto k = static_cast<Eigen::Index>(angles.size());
  const Eigen::VectorXd b0 = in.vector("/mlr/beta0", k), b1 = in.vector("/mlr/beta1_per_m_min", k),
                        b2 = in.vector("/mlr/beta2_per_mpa", k), lo = in.vector("/mlr/mu_min", k),
                        hi = in.vector("/mlr/mu_max", k), r2 = in.vector("/mlr/r_squared", k);
  std::vector<MlrRow> rows;
  for (Eigen::Index i = 0; i < k; ++i) {
    rows.push_back({angles[static_cast<size_t>(i)], b0(i), b1(i), b2(i), lo(i), hi(i), r2(i)});
  }
  return MlrLaw(std::move(rows), in.string_attribute("/mlr", "source"), std::move(inputs));
}

// ---- Gaussian process ----------------------------------------------------------------------
namespace {

// A stored fast evaluator, refused unless its checksum matches and sampled nodes are the exact model's.
void write_fast_evaluator(h5::Writer& out, const FastEvaluator& fast, const std::string& group) {
  const std::vector<long long> cells(fast.grid().cells().begin(), fast.grid().cells().end());
  const FastEvaluatorBounds& b = fast.bounds();
  out.group(group);
  out.string_attribute(group, "interpolation",
                       "piecewise-cubic tensor Lagrange on a uniform grid over the unit box; node values (mu, log std), "
                       "node-major, last input fastest; bounds measured against the exact model");
  out.ints(group + "/cells", cells);
  out.doubles(group + "/values", fast.grid().values());
  out.double_attribute(group, "bound_mu_absolute", b.mu_absolute);
  out.double_attribute(group, "bound_std_relative", b.std_relative);
  out.double_attribute(group, "std_floor", b.std_floor);
  out.string_attribute(group, "sha256", fast_evaluator_digest(cells, fast.grid().values(), b));
}

std::shared_ptr<const FastEvaluator> read_fast_evaluator(const h5::Reader& in, const FrictionModel& gp,
                                                         const std::string& group) {
  const std::vector<long long> cells = in.ints(group + "/cells");
  const std::vector<double> values = in.doubles(group + "/values");
  const FastEvaluatorBounds bounds{
      in.double_attribute(group, "bound_mu_absolute"), in.double_attribute(group, "bound_std_relative"),
      in.has_attribute(group, "std_floor") ? in.double_attribute(group, "std_floor") : 0.0};
  if (fast_evaluator_digest(cells, values, bounds) !=
      in.string_attribute(group, "sha256")) {
    in.fail(group, "checksum mismatch: the interpolant or its bounds changed after it was certified");
  }
  if (cells.size() != gp.inputs().size()) {
    in.fail(group + "/cells", "has " + std::to_string(cells.size()) + " entries for " +
                                  std::to_string(gp.inputs().size()) + " inputs");
  }
  std::vector<int> shape;
  for (const long long c : cells) {
    if (c < TensorCubicGrid::kMinimumCells || c > std::numeric_limits<int>::max()) in.fail(group + "/cells", "out of range");
    shape.push_back(static_cast<int>(c));
  }
  long long nodes = 0;
  try {
    nodes = TensorCubicGrid::node_count(shape);
  } catch (const Error& e) {
    in.fail(group + "/cells", e.what());
  }
  if (static_cast<long long>(values.size()) != 2 * nodes) {
    in.fail(group + "/values", "has " + std::to_string(values.size()) + " values for " +
                                   std::to_string(TensorCubicGrid::node_count(shape)) + " nodes of 2 outputs");
  }
  const Eigen::MatrixXd node_values =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(values.data(),
                                                                                   static_cast<Eigen::Index>(values.size() / 2), 2);
  std::shared_ptr<const FastEvaluator> fast;
  try {
    fast = std::make_shared<const FastEvaluator>(gp.inputs(), TensorCubicGrid(shape, node_values), bounds);
  } catch (const Error& e) {
    in.fail(group, e.what());
  }
  // Spot check: evenly spaced nodes against the exact model (a grid from another model fails here).
  const Eigen::MatrixXd all_nodes = TensorCubicGrid::nodes(shape);
  const long long count = all_nodes.rows(), checks = std::min(count, kFastSpotChecks);
  Eigen::MatrixXd x(checks, all_nodes.cols());
  std::vector<long long> which;
  for (long long c = 0; c < checks; ++c) {
    which.push_back(c * (count - 1) / std::max(1LL, checks - 1));
    for (Eigen::Index k = 0; k < x.cols(); ++k) {
      const auto& input = gp.inputs()[static_cast<size_t>(k)];
      x(c, k) = input.lo + all_nodes(which.back(), k) * (input.hi - input.lo);
    }
  }
  EvaluationRequest exact{.std = true};
  exact.mu_tolerance = 0.0;
  const Evaluation e = gp.evaluate(x, exact);
  const double mu_tolerance = std::max(kFastNodeRoundingFloor, bounds.mu_absolute);
  const double std_tolerance = std::max(kFastNodeRoundingFloor, bounds.std_relative);
  for (long long c = 0; c < checks; ++c) {
    const double mu = values[static_cast<size_t>(2 * which[static_cast<size_t>(c)])];
    const double std = std::exp(values[static_cast<size_t>(2 * which[static_cast<size_t>(c)] + 1)]);
    const double std_scale = std::max({e.std(c), bounds.std_floor, kSmallestTabulatedStd});
    if (!(std::abs(mu - e.mu(c)) <= mu_tolerance) || !(std::abs(std - e.std(c)) <= std_tolerance * std_scale)) {
      char what[256];
      std::snprintf(what, sizeof what,
                    "node %lld is not the model's value there (mu %.17g against %.17g, std %.17g against %.17g; "
                    "certified within %.3g and %.3g of max(std, %.3g))",
                    which[static_cast<size_t>(c)], mu, e.mu(c), std, e.std(c), mu_tolerance, std_tolerance, bounds.std_floor);
      in.fail(group + "/values", what);
    }
  }
  return fast;
}

}  // namespace

void GaussianProcess::write(h5::Writer& out) const { write_group(out, "/gp"); }

void GaussianProcess::write_group(h5::Writer& out, const std::string& group) const {
  const auto& s = state_;
  const std::string summary_group = group + "/training", fast_group = group + "/fast_evaluator";
  out.group(group);
  out.string_attribute(group, "kernel", "constant*RBF(ARD)+white; inputs scaled to the unit box, outputs (mu-mean)/scale");
  out.double_attribute(group, "y_mean", s.y_mean);
  out.double_attribute(group, "y_scale", s.y_scale);
  out.double_attribute(group, "signal_variance", s.hyper.signal_variance);
  out.double_attribute(group, "noise_variance", s.hyper.noise_variance);
  out.int_attribute(group, "noise_term", s.hyper.noise_term ? 1 : 0);
  out.double_attribute(group, "jitter", s.jitter);
  out.doubles(group + "/length_scales", s.hyper.length_scales);
  out.matrix(group + "/x_train", s.x_train);
  out.doubles(group + "/y_train", s.y_train);
  out.doubles(group + "/alpha", s.alpha);
  if (s.x_train.rows() <= kStoreCholeskyUpTo) out.matrix(group + "/cholesky_lower", s.cholesky);
  if (s.known_noise.size() != 0) out.doubles(group + "/known_noise", s.known_noise);
  out.double_attribute(group, "micro_std_error", s.micro_std_error);
  out.string_attribute(group, "interval", std::string(to_string(interval_meaning())));
  out.string_attribute(group, "constant_mean", s.mean_estimated ? "estimated" : "average");
  out.group(summary_group);
  for (const auto& [name, field] : kSummaryNumbers) out.double_attribute(summary_group, name, s.summary.*field);
  for (const auto& [name, field] : kSummaryCounts) out.int_attribute(summary_group, name, s.summary.*field);
  for (const auto& [name, field] : kSummaryTexts) out.string_attribute(summary_group, name, s.summary.*field);
  out.string_attribute(summary_group, kSummaryDatasetDescription, s.summary.dataset_description);
  out.double_attribute(summary_group, kSummaryStandardisedRms, s.summary.loo_standardised_rms);
  if (fast_) write_fast_evaluator(out, *fast_, fast_group);
  if (patch_scatter_) patch_scatter_->write_group(out, group + "/patch_scatter");
}

GaussianProcess GaussianProcess::read(const h5::Reader& in, InputSpace inputs) { return read_group(in, std::move(inputs), "/gp"); }

GaussianProcess GaussianProcess::read_group(const h5::Reader& in, InputSpace inputs, const std::string& group) {
  const std::string summary_group = group + "/training", fast_group = group + "/fast_evaluator";
  State s;
  s.inputs = std::move(inputs);
  const auto d = static_cast<Eigen::Index>(s.inputs.size());
  s.x_train = in.matrix(group + "/x_train");
  if (s.x_train.cols() != d) {
    in.fail(group + "/x_train", "has " + std::to_string(s.x_train.cols()) + " columns for " + std::to_string(d) + " inputs");
  }
  const Eigen::Index n = s.x_train.rows();
  if (n == 0) in.fail(group + "/x_train", "no training points");
  if (!s.x_train.allFinite()) in.fail(group + "/x_train", "contains non-finite values");
  s.y_train = in.vector(group + "/y_train", n);
  s.alpha = in.vector(group + "/alpha", n);
  if (!s.alpha.allFinite()) in.fail(group + "/alpha", "contains non-finite values");
  s.y_mean = in.double_attribute(group, "y_mean");
  s.y_scale = in.double_attribute(group, "y_scale");
  s.hyper.signal_variance = in.double_attribute(group, "signal_variance");
  s.hyper.noise_variance = in.double_attribute(group, "noise_variance");
  s.hyper.noise_term = in.int_attribute(group, "noise_term") != 0;
  s.hyper.length_scales = in.vector(group + "/length_scales", d);
  s.jitter = in.double_attribute(group, "jitter");
  if (!(s.hyper.length_scales.array() > 0).all() || !s.hyper.length_scales.allFinite()) {
    in.fail(group + "/length_scales", "must be positive and finite");
  }
  if (!(s.hyper.signal_variance > 0) || !std::isfinite(s.hyper.signal_variance)) {
    in.fail(group, "attribute signal_variance must be positive and finite");
  }
  if (!(s.hyper.noise_variance >= 0) || !std::isfinite(s.hyper.noise_variance)) {
    in.fail(group, "attribute noise_variance must be >= 0 and finite");
  }
  if (!(s.jitter >= 0) || !std::isfinite(s.jitter)) in.fail(group, "attribute jitter must be >= 0 and finite");
  if (!(s.y_scale > 0) || !std::isfinite(s.y_scale)) in.fail(group, "attribute y_scale must be positive and finite");
  if (in.has(group + "/known_noise")) {
    s.known_noise = in.vector(group + "/known_noise", n);
    if (!s.known_noise.allFinite() || !(s.known_noise.array() >= 0).all()) in.fail(group + "/known_noise", "must be finite and >= 0");
  }
  if (in.has_attribute(group, "micro_std_error")) {
    s.micro_std_error = in.double_attribute(group, "micro_std_error");
    if (!(s.micro_std_error >= 0) || !std::isfinite(s.micro_std_error)) {
      in.fail(group, "attribute micro_std_error must be >= 0 and finite");
    }
  }

  // Absent (files before issue 33): new-run or shared-scatter, by micro_std_error.
  if (in.has_attribute(group, "interval")) {
    const std::string meaning = in.string_attribute(group, "interval");
    if (meaning != "new-run" && meaning != "shared-scatter" && meaning != "mean-over-draws") {
      in.fail(group, "attribute interval '" + meaning + "' is not new-run, shared-scatter or mean-over-draws");
    }
    s.interval_of_mean = meaning == "mean-over-draws";
  }

  // Absent (files before the trend term): the average, as known (simple kriging).
  if (in.has_attribute(group, "constant_mean")) {
    const std::string mean = in.string_attribute(group, "constant_mean");
    if (mean != "estimated" && mean != "average") in.fail(group, "attribute constant_mean '" + mean + "' is not estimated or average");
    s.mean_estimated = mean == "estimated";
  }

  Eigen::MatrixXd kf;
  rbf_signal_covariance(to_unit_box(s.x_train, s.inputs), s.hyper, kf);
  // Known per-point noise belongs to the covariance the factor was made of.
  if (s.known_noise.size() != 0) kf.diagonal() += s.known_noise;
  const double diagonal = s.hyper.noise_variance + s.jitter;
  if (in.has(group + "/cholesky_lower")) {
    s.cholesky = in.matrix(group + "/cholesky_lower");
    if (s.cholesky.rows() != n || s.cholesky.cols() != n) in.fail(group + "/cholesky_lower", "is not n × n");
    if (!s.cholesky.allFinite() || !(s.cholesky.diagonal().array() > 0).all()) {
      in.fail(group + "/cholesky_lower", "is not a valid Cholesky factor (non-finite or non-positive diagonal)");
    }
    if (!factor_matches_kernel(s.cholesky, kf, diagonal)) {
      in.fail(group + "/cholesky_lower", "is inconsistent with x_train and the hyper-parameters (L·Lᵀ != K)");
    }
  } else {
    const auto chol = cholesky_with_jitter(kf, diagonal, s.cholesky);
    if (!chol.ok || chol.jitter > 0.0) in.fail(group, "covariance cannot be refactorised with the stored jitter");
  }
  // Consistency, O(n²): α̂ = (L Lᵀ)⁻¹ y from the factor, then K α = y and α = α̂ entry by entry. Every
  // scale below comes from α̂ as well as from α: scaled by ‖α‖ alone, one entry blown up to 1e180 by a
  // flipped exponent bit inflated its own tolerance and passed.
  if (!s.y_train.allFinite()) in.fail(group + "/y_train", "contains non-finite values");
  if (!std::isfinite(s.y_mean)) in.fail(group, "attribute y_mean must be finite");
  const Eigen::VectorXd y = (s.y_train.array() - s.y_mean) / s.y_scale;
  Eigen::VectorXd alpha_from_factor = s.cholesky.triangularView<Eigen::Lower>().solve(y);
  s.cholesky.triangularView<Eigen::Lower>().transpose().solveInPlace(alpha_from_factor);
  const double alpha_size = std::min(s.alpha.lpNorm<Eigen::Infinity>(), alpha_from_factor.lpNorm<Eigen::Infinity>());
  if ((alpha_from_factor - s.alpha).lpNorm<Eigen::Infinity>() > kAlphaRecomputeTolerance * alpha_size) {
    in.fail(group + "/alpha", "is inconsistent with the Cholesky factor and y_train (alpha != K⁻¹y)");
  }
  Eigen::VectorXd k_alpha = kf.selfadjointView<Eigen::Lower>() * s.alpha;
  k_alpha += diagonal * s.alpha;
  const double n_alpha = static_cast<double>(n) * alpha_size;
  const double scale = (kf.lpNorm<Eigen::Infinity>() + diagonal) * n_alpha + y.lpNorm<Eigen::Infinity>();
  if ((k_alpha - y).lpNorm<Eigen::Infinity>() > kLoadBackwardErrorTolerance * scale) {
    in.fail(group + "/alpha", "is inconsistent with x_train, y_train and the hyper-parameters (K·alpha != y)");
  }
  // The generalised-least-squares constant makes the residuals K-orthogonal to it: 1ᵀK⁻¹(y − β̂1) = 1ᵀα = 0.
  if (s.mean_estimated && std::abs(s.alpha.sum()) > kAlphaRecomputeTolerance * n_alpha) {
    in.fail(group, "attribute y_mean is not the estimated constant mean of constant_mean = estimated (sum of alpha != 0)");
  }
  if (in.has(summary_group)) {
    for (const auto& [name, field] : kSummaryNumbers) s.summary.*field = in.double_attribute(summary_group, name);
    for (const auto& [name, field] : kSummaryCounts) s.summary.*field = in.int_attribute(summary_group, name);
    for (const auto& [name, field] : kSummaryTexts) s.summary.*field = in.string_attribute(summary_group, name);
    if (in.has_attribute(summary_group, kSummaryDatasetDescription)) {
      s.summary.dataset_description = in.string_attribute(summary_group, kSummaryDatasetDescription);
    }
    if (in.has_attribute(summary_group, kSummaryStandardisedRms)) {
      s.summary.loo_standardised_rms = in.double_attribute(summary_group, kSummaryStandardisedRms);
    } else if (s.x_train.rows() <= kMostPointsForLooAtLoad) {
      GpTrainingSummary recomputed;
      leave_one_out(s, recomputed);
      s.summary.loo_standardised_rms = recomputed.loo_standardised_rms;
    }
  }
  const InputSpace inputs_of_model = s.inputs;
  GaussianProcess gp(std::move(s));
  if (group.ends_with("/patch_scatter")) gp.set_unbounded_output();  // before its grid's load check
  if (in.has(fast_group)) gp.attach_fast_evaluator(read_fast_evaluator(in, gp, fast_group));
  // Only a model's own GP has a patch scatter (a scatter of the scatter is not a thing, and a file
  // nesting them deeply would recurse here); a calibrated model's emulator is one.
  if (!group.ends_with("/patch_scatter") && in.has(group + "/patch_scatter")) {
    gp.attach_patch_scatter(std::make_shared<const GaussianProcess>(read_group(in, inputs_of_model, group + "/patch_scatter")));
  }
  return gp;
}

namespace {
constexpr const char* kCalibratedGroup = "/calibrated";
const std::vector<std::string> kPosteriorColumns = {"mean", "sd", "lo95", "median", "hi95", "split_rhat", "effective_sample_size"};

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ",") + name;
  return text;
}

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> names;
  std::string name;
  for (const char c : text + ",") {
    if (c != ',') {
      name += c;
    } else if (!name.empty()) {
      names.push_back(name);
      name.clear();
    }
  }
  return names;
}
}  // namespace

void CalibratedModel::write(h5::Writer& out) const {
  const std::string g = kCalibratedGroup;
  const CalibrationProblem& p = problem();
  out.group(g);
  out.string_attribute(g, "meaning",
                       "mu(x) = mean over posterior samples s of E[eta(x, theta_s) + delta(x) | measurements]; std the "
                       "mixture's (Kennedy & O'Hagan 2001, eq. 6); the emulator is the campaign's GP over the conditions "
                       "and the law's coefficients");
  write_input_space(out, emulator_->inputs(), g + "/emulator_inputs");
  emulator_->write_group(out, g + "/emulator");
  const Measurements& data = p.data();
  out.group(g + "/measurements");
  out.strings(g + "/measurements/condition_names", data.condition_names);
  out.matrix(g + "/measurements/conditions", data.conditions);
  out.doubles(g + "/measurements/mu", data.mu);
  out.doubles(g + "/measurements/mu_sd", data.mu_sd);
  out.strings(g + "/measurements/row_names", data.row_names);
  // Conditions known within an uncertainty, and the data sets (both absent in files before them).
  out.matrix(g + "/measurements/condition_sd", data.condition_sd);
  out.matrix(g + "/measurements/condition_half_width", data.condition_half_width);
  out.strings(g + "/measurements/data_sets", data.data_sets);
  out.ints(g + "/measurements/data_set_of_row", std::vector<long long>(data.data_set_of_row.begin(), data.data_set_of_row.end()));
  out.string_attribute(g, "parameters", joined(p.parameters()));
  // Held inputs: names and values (files before them held an input as a constant condition column).
  std::vector<std::string> held_names;
  std::vector<double> held_values;
  for (const auto& [name, value] : p.held()) {
    held_names.push_back(name);
    held_values.push_back(value);
  }
  out.string_attribute(g, "held", "");
  out.strings(g + "/held_inputs", held_names);
  out.doubles(g + "/held_values", held_values);
  out.int_attribute(g, "discrepancy", p.discrepancy() ? 1 : 0);
  // Each biased data set's name and its prior (kind, a, b): what the posterior's bias columns mean.
  std::vector<std::string> bias_sets;
  h5::RowMatrix bias_priors(static_cast<Eigen::Index>(p.priors().biases.size()), 3);
  for (size_t b = 0; b < p.priors().biases.size(); ++b) {
    const auto& [name, prior] = p.priors().biases[b];
    bias_sets.push_back(name);
    bias_priors.row(static_cast<Eigen::Index>(b)) << static_cast<double>(prior.kind), prior.a, prior.b;
  }
  out.strings(g + "/bias_sets", bias_sets);
  out.matrix(g + "/bias_priors", bias_priors);
  out.matrix(g + "/samples", samples());
  out.string_attribute(g, "data_source", record_.data_source);
  out.string_attribute(g, "priors", record_.priors);
  out.int_attribute(g, "walkers", record_.walkers);
  out.int_attribute(g, "steps", record_.steps);
  out.int_attribute(g, "burn_in_steps", record_.burn_in_steps);
  out.int_attribute(g, "seed", static_cast<long long>(record_.seed));
  out.double_attribute(g, "acceptance", record_.acceptance);
  std::vector<std::string> names;
  Eigen::MatrixXd table(static_cast<Eigen::Index>(record_.posterior.size()), static_cast<Eigen::Index>(kPosteriorColumns.size()));
  for (size_t j = 0; j < record_.posterior.size(); ++j) {
    const ParameterSummary& q = record_.posterior[j];
    names.push_back(q.name);
    table.row(static_cast<Eigen::Index>(j)) << q.mean, q.sd, q.lo95, q.median, q.hi95, q.split_rhat, q.effective_sample_size;
  }
  out.group(g + "/posterior");
  out.string_attribute(g + "/posterior", "columns", joined(kPosteriorColumns));
  out.strings(g + "/posterior/names", names);
  out.matrix(g + "/posterior/summary", table);
  if (fast_) write_fast_evaluator(out, *fast_, g + "/fast_evaluator");
}

CalibratedModel CalibratedModel::read(const h5::Reader& in, InputSpace inputs) {
  const std::string g = kCalibratedGroup;
  InputSpace emulator_inputs = read_input_space(in, g + "/emulator_inputs");
  auto emulator = std::make_shared<const GaussianProcess>(GaussianProcess::read_group(in, emulator_inputs, g + "/emulator"));
  Measurements data;
  data.condition_names = in.strings(g + "/measurements/condition_names");
  data.conditions = in.matrix(g + "/measurements/conditions");
  const auto rows = data.conditions.rows();
  if (data.conditions.cols() != static_cast<Eigen::Index>(data.condition_names.size())) {
    in.fail(g + "/measurements/conditions", "has " + std::to_string(data.conditions.cols()) + " columns for " +
                                               std::to_string(data.condition_names.size()) + " condition names");
  }
  data.mu = in.vector(g + "/measurements/mu", rows);
  data.mu_sd = in.vector(g + "/measurements/mu_sd", rows);
  data.row_names = in.strings(g + "/measurements/row_names");
  if (static_cast<Eigen::Index>(data.row_names.size()) != rows) in.fail(g + "/measurements/row_names", "not one per measurement");
  if (in.has(g + "/measurements/condition_sd")) {
    data.condition_sd = in.matrix(g + "/measurements/condition_sd");
    data.condition_half_width = in.matrix(g + "/measurements/condition_half_width");
    for (const auto* m : {&data.condition_sd, &data.condition_half_width}) {
      if (m->rows() != rows || m->cols() != data.conditions.cols() || !m->allFinite() || (m->array() < 0.0).any()) {
        in.fail(g + "/measurements/condition_sd", "the conditions' uncertainties must be finite, non-negative, one per condition");
      }
    }
    data.data_sets = in.strings(g + "/measurements/data_sets");
    for (const long long k : in.ints(g + "/measurements/data_set_of_row")) {
      if (k < 0 || k >= static_cast<long long>(data.data_sets.size())) in.fail(g + "/measurements/data_set_of_row", "names no data set");
      data.data_set_of_row.push_back(static_cast<int>(k));
    }
    if (static_cast<Eigen::Index>(data.data_set_of_row.size()) != rows) in.fail(g + "/measurements/data_set_of_row", "not one per measurement");
  }
  std::vector<std::pair<std::string, double>> held;
  if (in.has(g + "/held_inputs")) {
    const std::vector<std::string> names = in.strings(g + "/held_inputs");
    const std::vector<double> values = in.doubles(g + "/held_values");
    if (names.size() != values.size()) in.fail(g + "/held_values", "not one per held input");
    for (size_t h = 0; h < names.size(); ++h) held.emplace_back(names[h], values[h]);
  }
  // Files before held inputs had their own: a constant condition column named in "held".
  for (const std::string& name : split_names(in.string_attribute(g, "held"))) {
    const auto found = std::find(data.condition_names.begin(), data.condition_names.end(), name);
    if (found == data.condition_names.end()) in.fail(g, "held input '" + name + "' is not among the measurements' conditions");
    const auto c = static_cast<Eigen::Index>(found - data.condition_names.begin());
    if (!(data.conditions.col(c).array() == data.conditions(0, c)).all()) in.fail(g, "held input '" + name + "' differs between rows");
    held.emplace_back(name, data.conditions(0, c));
    data.condition_names.erase(found);
    auto drop = [c](Eigen::MatrixXd& m) {
      if (m.size() == 0) return;
      Eigen::MatrixXd kept(m.rows(), m.cols() - 1);
      kept << m.leftCols(c), m.rightCols(m.cols() - c - 1);
      m = kept;
    };
    drop(data.conditions);
    drop(data.condition_sd);
    drop(data.condition_half_width);
  }
  CalibrationPriors priors;
  priors.discrepancy = in.int_attribute(g, "discrepancy") != 0;
  if (in.has(g + "/bias_sets")) {
    const std::vector<std::string> sets = in.strings(g + "/bias_sets");
    const Eigen::MatrixXd bias_priors = in.matrix(g + "/bias_priors");
    if (bias_priors.rows() != static_cast<Eigen::Index>(sets.size()) || (!sets.empty() && bias_priors.cols() != 3)) {
      in.fail(g + "/bias_priors", "one row (kind, a, b) per biased data set");
    }
    for (size_t b = 0; b < sets.size(); ++b) {
      const double kind = bias_priors(static_cast<Eigen::Index>(b), 0);
      if (!(kind >= 0.0 && kind <= static_cast<double>(PriorKind::half_normal) && kind == std::floor(kind))) {
        in.fail(g + "/bias_priors", "an unknown prior kind");
      }
      Prior prior{static_cast<PriorKind>(static_cast<int>(kind)), bias_priors(static_cast<Eigen::Index>(b), 1),
                  bias_priors(static_cast<Eigen::Index>(b), 2)};
      try {
        prior.check(g + "/bias_priors");
      } catch (const Error& e) {
        in.fail(g + "/bias_priors", e.what());
      }
      priors.biases.emplace_back(sets[b], prior);
    }
  }
  const std::vector<std::string> parameters = split_names(in.string_attribute(g, "parameters"));
  const Eigen::MatrixXd samples = in.matrix(g + "/samples");
  auto problem = std::make_shared<const CalibrationProblem>(emulator, std::move(data), parameters, priors, held);
  if (samples.cols() != problem->dimension() || samples.rows() < 1 || !samples.allFinite()) {
    in.fail(g + "/samples", "must hold one finite row per posterior sample, " + std::to_string(problem->dimension()) + " columns");
  }
  CalibrationRecord record;
  record.data_source = in.string_attribute(g, "data_source");
  record.priors = in.string_attribute(g, "priors");
  record.walkers = static_cast<int>(in.int_attribute(g, "walkers"));
  record.steps = static_cast<int>(in.int_attribute(g, "steps"));
  record.burn_in_steps = static_cast<int>(in.int_attribute(g, "burn_in_steps"));
  record.seed = static_cast<unsigned long long>(in.int_attribute(g, "seed"));
  record.acceptance = in.double_attribute(g, "acceptance");
  const std::vector<std::string> names = in.strings(g + "/posterior/names");
  const Eigen::MatrixXd table = in.matrix(g + "/posterior/summary");
  if (table.rows() != static_cast<Eigen::Index>(names.size()) || table.cols() != static_cast<Eigen::Index>(kPosteriorColumns.size())) {
    in.fail(g + "/posterior/summary", "must have one row per name and " + std::to_string(kPosteriorColumns.size()) + " columns");
  }
  for (size_t j = 0; j < names.size(); ++j) {
    const auto r = table.row(static_cast<Eigen::Index>(j));
    record.posterior.push_back({names[j], r(0), r(1), r(2), r(4), r(3), r(5), r(6)});
  }
  CalibratedModel model(std::make_shared<const CalibratedPosterior>(std::move(problem), samples), std::move(record));
  if (!same_input_space(model.inputs(), inputs)) in.fail("/inputs", "are not the calibrated model's served inputs");
  if (in.has(g + "/fast_evaluator")) model.attach_fast_evaluator(read_fast_evaluator(in, model, g + "/fast_evaluator"));
  return model;
}

}  // namespace mufric
