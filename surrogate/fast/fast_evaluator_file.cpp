#include "surrogate/fast/fast_evaluator_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "common/error.hpp"
#include "common/files.hpp"

namespace mufric {
namespace {

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

}  // namespace


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


}  // namespace mufric
