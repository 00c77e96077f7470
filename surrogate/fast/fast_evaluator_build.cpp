#include "surrogate/fast/fast_evaluator_build.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <random>

#include "common/error.hpp"
#include "surrogate/core/vector_exp.hpp"

namespace mufric {
namespace {

// Grid sizes: cells per input = clamp(ceil(resolution / length scale in unit-box coordinates)).
constexpr double kFirstResolution = 4.0;
constexpr int kMaximumCellsPerInput = 4096;
// Between refinements the resolution grows by the O(h⁴) prediction, within these factors.
constexpr double kLeastGrowth = 1.25;
constexpr double kMostGrowth = 3.0;
constexpr double kGrowthMargin = 1.1;
// The local searches for the worst error: evaluations each (BOBYQA, Powell 2009).
constexpr int kLocalSearchEvaluations = 60;
// Random points per refinement round: enough to steer the next grid's size; the certification of
// the final grid uses the options' full check set and the local searches.
constexpr long long kRefinementCheckPoints = 2000;
// A search evaluates one point per call, several times dearer than a point of a batch (measured
// ~4× at n = 900); the work count takes each as this many batch points.
constexpr double kSearchEvaluationCost = 4.0;

// What the grid is built from and measured against: the exact GP, never a grid the GP may already
// carry (upgrade --rebuild, a GP loaded from a file with one).
EvaluationRequest exact_with_std() {
  EvaluationRequest what{.std = true};
  what.mu_tolerance = what.std_relative_tolerance = 0.0;
  return what;
}

std::vector<int> cells_for(const GridSource& source, double resolution) {
  std::vector<int> cells;
  const Eigen::VectorXd& l = source.unit_length_scales;
  for (Eigen::Index k = 0; k < l.size(); ++k) {
    const double wanted = std::ceil(resolution / l(k));
    cells.push_back(static_cast<int>(
        std::clamp(wanted, static_cast<double>(TensorCubicGrid::kMinimumCells), static_cast<double>(kMaximumCellsPerInput))));
  }
  return cells;
}

bool every_input_at_finest(const std::vector<int>& cells) {
  return std::all_of(cells.begin(), cells.end(), [](int c) { return c >= kMaximumCellsPerInput; });
}

double grid_megabytes(const std::vector<int>& cells) {
  return static_cast<double>(TensorCubicGrid::node_count(cells)) * 2.0 * sizeof(double) / 1e6;
}

Eigen::MatrixXd to_si(const Eigen::MatrixXd& u, const InputSpace& box) {
  Eigen::MatrixXd x(u.rows(), u.cols());
  for (Eigen::Index k = 0; k < u.cols(); ++k) {
    const auto& in = box[static_cast<size_t>(k)];
    x.col(k) = (in.lo + u.col(k).array() * (in.hi - in.lo)).matrix();
  }
  return x;
}

// The exact μ and log σ at every node of a grid.
TensorCubicGrid tabulate(const FrictionModel& model, const std::vector<int>& cells) {
  const Eigen::MatrixXd x = to_si(TensorCubicGrid::nodes(cells), model.inputs());
  const Evaluation e = model.evaluate(x, exact_with_std());
  Eigen::MatrixXd values(x.rows(), 2);
  values.col(0) = e.mu;
  values.col(1) = e.std.array().max(kSmallestTabulatedStd).log().matrix();
  return TensorCubicGrid(cells, values);
}



using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Errors of one point, each over its tolerance: the larger one is what the searches maximise.
struct PointError {
  double mu_absolute = 0.0, std_relative = 0.0;
  double score(const FastEvaluatorOptions& o) const {
    return std::max(mu_absolute / o.mu_tolerance, std_relative / o.std_relative_tolerance);
  }
};

// σ's error against max(σ, the bounds' floor): see "What σ's tolerance means" in the header.
PointError error_at(const FastEvaluator& fast, double mu, double std, const double* x) {
  double mu_fast = 0.0, std_fast = 0.0;
  fast.evaluate(x, mu_fast, std_fast);
  const double std_scale = std::max({std, fast.bounds().std_floor, kSmallestTabulatedStd});
  return {std::abs(mu_fast - mu), std::abs(std_fast - std) / std_scale};
}

// Every point's error against the exact model at the points x (SI, one row each), and the largest.
struct MeasuredErrors {
  std::vector<PointError> per_point;
  PointError worst;
};
MeasuredErrors point_errors(const FastEvaluator& fast, const FrictionModel& model, const Eigen::MatrixXd& x) {
  const Evaluation exact = model.evaluate(x, exact_with_std());
  MeasuredErrors m;
  m.per_point.resize(static_cast<size_t>(x.rows()));
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Eigen::RowVectorXd row = x.row(i);
    const PointError p = error_at(fast, exact.mu(i), exact.std(i), row.data());
    m.per_point[static_cast<size_t>(i)] = p;
    m.worst.mu_absolute = std::max(m.worst.mu_absolute, p.mu_absolute);
    m.worst.std_relative = std::max(m.worst.std_relative, p.std_relative);
  }
  return m;
}

struct SearchContext {
  const FastEvaluator* fast;
  const FrictionModel* model;
  const FastEvaluatorOptions* options;
  PointError worst;
};

double search_objective(unsigned d, const double* u, double*, void* data) {
  auto* c = static_cast<SearchContext*>(data);
  Eigen::RowVectorXd x(d);
  for (unsigned k = 0; k < d; ++k) {
    const auto& in = c->fast->box()[k];
    x(k) = in.lo + std::clamp(u[k], 0.0, 1.0) * (in.hi - in.lo);
  }
  const Evaluation e = c->model->evaluate(x, exact_with_std());
  const PointError p = error_at(*c->fast, e.mu(0), e.std(0), x.data());
  c->worst.mu_absolute = std::max(c->worst.mu_absolute, p.mu_absolute);
  c->worst.std_relative = std::max(c->worst.std_relative, p.std_relative);
  return p.score(*c->options);
}

// Measured on a fresh random set, then (final grid only) local searches from its worst points.
FastEvaluatorBounds measured_bounds(const FastEvaluator& fast, const FrictionModel& model,
                                    const FastEvaluatorOptions& o, unsigned seed, bool search) {
  const auto d = static_cast<Eigen::Index>(model.inputs().size());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const long long checks = search ? o.check_points : std::min(o.check_points, kRefinementCheckPoints);
  Eigen::MatrixXd u(checks, d);
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    for (Eigen::Index k = 0; k < d; ++k) u(i, k) = uniform(rng);
  }
  const MeasuredErrors measured = point_errors(fast, model, to_si(u, model.inputs()));
  const std::vector<PointError>& errors = measured.per_point;
  PointError worst = measured.worst;
  if (search && o.local_searches > 0) {
    std::vector<size_t> order(errors.size());
    std::iota(order.begin(), order.end(), size_t{0});
    const size_t starts = std::min(order.size(), static_cast<size_t>(o.local_searches));
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(starts), order.end(),
                      [&](size_t a, size_t b) { return errors[a].score(o) > errors[b].score(o); });
    SearchContext context{&fast, &model, &o, worst};
    for (size_t s = 0; s < starts; ++s) {
      nlopt_opt opt = nlopt_create(NLOPT_LN_BOBYQA, static_cast<unsigned>(d));
      const std::vector<double> lower(static_cast<size_t>(d), 0.0), upper(static_cast<size_t>(d), 1.0);
      nlopt_set_lower_bounds(opt, lower.data());
      nlopt_set_upper_bounds(opt, upper.data());
      nlopt_set_max_objective(opt, search_objective, &context);
      nlopt_set_maxeval(opt, kLocalSearchEvaluations);
      // A step of a fraction of the smallest cell: the error varies within one cell.
      std::vector<double> step(static_cast<size_t>(d));
      for (Eigen::Index k = 0; k < d; ++k) step[static_cast<size_t>(k)] = 0.25 / fast.grid().cells()[static_cast<size_t>(k)];
      nlopt_set_initial_step(opt, step.data());
      const Eigen::RowVectorXd row = u.row(static_cast<Eigen::Index>(order[s]));
      std::vector<double> start(row.data(), row.data() + d);
      double best = 0.0;
      nlopt_optimize(opt, start.data(), &best);  // the worst seen is in the context, whatever the outcome
      nlopt_destroy(opt);
    }
    worst = context.worst;
  }
  return {FastEvaluator::kBoundSafetyFactor * worst.mu_absolute, FastEvaluator::kBoundSafetyFactor * worst.std_relative,
          fast.bounds().std_floor};
}

std::string shape_text(const std::vector<int>& cells) {
  std::string shape;
  for (const int c : cells) {
    if (!shape.empty()) shape += 'x';
    shape += std::to_string(c);
  }
  return shape;
}

}  // namespace

FastEvaluatorBounds measure_errors(const FastEvaluator& fast, const FrictionModel& model, const Eigen::MatrixXd& x) {
  const PointError worst = point_errors(fast, model, x).worst;
  return {worst.mu_absolute, worst.std_relative, fast.bounds().std_floor};
}


FastEvaluator build_fast_evaluator(const GridSource& source, const FastEvaluatorOptions& o) {
  const FrictionModel& model = source.model;
  if (!(o.mu_tolerance > 0.0) || !(o.std_relative_tolerance > 0.0)) {
    throw Error("fast evaluator: tolerances must be > 0");
  }
  if (o.check_points < 1) throw Error("fast evaluator: check_points must be >= 1");
  if (!(o.max_work > 0.0)) throw Error("fast evaluator: the work budget must be > 0");
  auto say = [&](const std::string& line) {
    if (o.progress) o.progress(line);
  };
  const Clock::time_point start = Clock::now();
  const FastEvaluatorBounds unmeasured{.std_floor = std_floor_for(o.mu_tolerance, o.std_relative_tolerance)};
  double resolution = kFirstResolution;
  if (source.unit_length_scales.size() != static_cast<Eigen::Index>(model.inputs().size()) ||
      !(source.unit_length_scales.array() > 0.0).all()) {
    throw Error("fast evaluator: one positive length scale per input is needed");
  }
  std::vector<int> cells = cells_for(source, resolution);
  const double per_point = source.point_work;
  double work_done = 0.0;
  if (grid_megabytes(cells) > o.max_megabytes) {
    throw FastEvaluatorOverCap("the coarsest grid needs " + std::to_string(grid_megabytes(cells)) +
                " MB, more than the cap of " + std::to_string(o.max_megabytes) + " MB");
  }
  char line[320];
  for (unsigned round = 0;; ++round) {
    FastEvaluator fast(model.inputs(), tabulate(model, cells), unmeasured);
    const FastEvaluatorBounds sampled = measured_bounds(fast, model, o, o.seed + round, false);
    work_done += per_point * static_cast<double>(TensorCubicGrid::node_count(cells) +
                                                 std::min(o.check_points, kRefinementCheckPoints));
    const double score = std::max(sampled.mu_absolute / o.mu_tolerance, sampled.std_relative / o.std_relative_tolerance);
    std::snprintf(line, sizeof line,
                  "grid %s cells (%.1f MB): mu within %.2e, std within %.2e of max(std, %.0e) (sampled); %.1f s so far",
                  shape_text(cells).c_str(), grid_megabytes(cells), sampled.mu_absolute, sampled.std_relative,
                  unmeasured.std_floor, seconds_since(start));
    say(line);
    const double growth = std::clamp(std::pow(score, 0.25) * kGrowthMargin, kLeastGrowth, kMostGrowth);
    double finer_resolution = resolution * growth;
    std::vector<int> finer = cells_for(source, finer_resolution);
    // Length scales of many box widths keep every input at the coarsest grid for several growths
    // (a model flat in its inputs): grow on until some input gets more cells or all have the most.
    while (finer == cells && !every_input_at_finest(cells)) finer = cells_for(source, finer_resolution *= growth);
    const double certification_work =
        per_point * (static_cast<double>(o.check_points) + o.local_searches * kLocalSearchEvaluations * kSearchEvaluationCost);
    const double next_round_work =
        per_point * static_cast<double>(TensorCubicGrid::node_count(finer) + std::min(o.check_points, kRefinementCheckPoints));
    std::string limit;
    if (finer == cells) {
      limit = "the finest grid (" + std::to_string(kMaximumCellsPerInput) + " cells per input) is reached";
    } else if (grid_megabytes(finer) > o.max_megabytes) {
      std::snprintf(line, sizeof line, "the next grid (%s cells, %.1f MB) exceeds the memory cap of %.1f MB",
                    shape_text(finer).c_str(), grid_megabytes(finer), o.max_megabytes);
      limit = line;
    } else if (work_done + next_round_work + certification_work > o.max_work) {
      std::snprintf(line, sizeof line, "the next grid (%s cells) would take %.3g G multiply-adds more, past the work budget of %.3g G",
                    shape_text(finer).c_str(), (next_round_work + certification_work) / 1e9, o.max_work / 1e9);
      limit = line;
    }
    if (score <= 1.0 || !limit.empty()) {
      // Certify this grid: the full check set and local searches from its worst points.
      fast.bounds_ = measured_bounds(fast, model, o, o.seed + 1000 + round, true);
      const bool meets = fast.meets(o.mu_tolerance, o.std_relative_tolerance);
      std::snprintf(line, sizeof line, "certified: mu within %.2e, std within %.2e of max(std, %.0e) (%s); %.1f s",
                    fast.bounds_.mu_absolute, fast.bounds_.std_relative, unmeasured.std_floor,
                    meets ? "meets the tolerances" : limit.empty() ? "refining" : "stopped", seconds_since(start));
      say(line);
      if (meets) return fast;
      if (!limit.empty()) {
        fast.stop_reason_ = limit;
        return fast;
      }
    }
    resolution = finer_resolution;
    cells = finer;
  }
}


std::string short_grid_refusal(const FastEvaluator& fast, const FastEvaluatorOptions& options) {
  if (fast.meets(options.mu_tolerance, options.std_relative_tolerance)) return "";
  if (fast.meets(kShortGridUsefulFactor * options.mu_tolerance, kShortGridUsefulFactor * options.std_relative_tolerance)) return "";
  char text[256];
  std::snprintf(text, sizeof text, "its bounds (mu %.3g, std %.3g relative) are more than %g times the tolerances (%.3g, %.3g)",
                fast.bounds().mu_absolute, fast.bounds().std_relative, kShortGridUsefulFactor, options.mu_tolerance,
                options.std_relative_tolerance);
  return text;
}

std::shared_ptr<const FastEvaluator> build_kept_fast_evaluator(const GridSource& source, const FastEvaluatorOptions& options,
                                                                const std::string& /*label*/) {
  std::shared_ptr<const FastEvaluator> fast;
  try {
    fast = std::make_shared<const FastEvaluator>(build_fast_evaluator(source, options));
  } catch (const FastEvaluatorOverCap&) {
    return nullptr;
  }
  return short_grid_refusal(*fast, options).empty() ? fast : nullptr;
}


}  // namespace mufric
