#include "surrogate/core/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <boost/random/sobol.hpp>

#include "common/error.hpp"

namespace mufric {

PlanDesign parse_plan_design(const std::string& name) {
  if (name == "random") return PlanDesign::random;
  if (name == "lhs" || name == "latin-hypercube") return PlanDesign::latin_hypercube;
  if (name == "sobol") return PlanDesign::sobol;
  throw Error("design '" + name + "': use random, lhs (latin-hypercube) or sobol");
}

std::string plan_design_name(PlanDesign design) {
  switch (design) {
    case PlanDesign::random: return "random";
    case PlanDesign::latin_hypercube: return "latin-hypercube";
    case PlanDesign::sobol: return "sobol";
  }
  return "unknown";
}

Eigen::MatrixXd latin_hypercube(Eigen::Index n, Eigen::Index d, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::MatrixXd u(n, d);
  std::vector<Eigen::Index> strata(static_cast<size_t>(n));
  for (Eigen::Index j = 0; j < d; ++j) {
    std::iota(strata.begin(), strata.end(), Eigen::Index{0});
    std::shuffle(strata.begin(), strata.end(), rng);
    for (Eigen::Index i = 0; i < n; ++i) {
      u(i, j) = (static_cast<double>(strata[static_cast<size_t>(i)]) + unit(rng)) / static_cast<double>(n);
    }
  }
  return u;
}

namespace {

Eigen::MatrixXd sobol_plan(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  using Engine = boost::random::sobol_engine<std::uint64_t, 64>;
  Engine sobol(static_cast<std::size_t>(d));  // starts after the all-zero point
  std::vector<std::uint64_t> shift(static_cast<size_t>(d), 0);
  if (seed != 0) {
    std::mt19937_64 rng(seed);
    for (auto& s : shift) s = rng();
  }
  constexpr double kTwoToMinus64 = 5.421010862427522e-20;  // 2^-64
  Eigen::MatrixXd u(n, d);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < d; ++j) u(i, j) = static_cast<double>(sobol() ^ shift[static_cast<size_t>(j)]) * kTwoToMinus64;
  }
  // 2^64 − small words round up to 1.0 in double: keep the half-open interval.
  return u.cwiseMin(std::nextafter(1.0, 0.0));
}

}  // namespace

Eigen::MatrixXd unit_plan(PlanDesign design, Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  if (n <= 0) throw Error("a sampling plan needs at least one point");
  if (d <= 0) throw Error("a sampling plan needs at least one input");
  switch (design) {
    case PlanDesign::random: {
      std::mt19937_64 rng(seed);
      std::uniform_real_distribution<double> unit(0.0, 1.0);
      Eigen::MatrixXd u(n, d);
      for (Eigen::Index i = 0; i < n; ++i) {
        for (Eigen::Index j = 0; j < d; ++j) u(i, j) = unit(rng);
      }
      return u;
    }
    case PlanDesign::latin_hypercube: {
      std::mt19937_64 rng(seed);
      return latin_hypercube(n, d, rng);
    }
    case PlanDesign::sobol: return sobol_plan(n, d, seed);
  }
  throw Error("unknown sampling design");
}

h5::RowMatrix plan_in_box(PlanDesign design, Eigen::Index n, const InputSpace& inputs, std::uint64_t seed) {
  const auto d = static_cast<Eigen::Index>(inputs.size());
  const Eigen::MatrixXd u = unit_plan(design, n, d, seed);
  h5::RowMatrix x(n, d);
  for (Eigen::Index j = 0; j < d; ++j) {
    const auto& input = inputs[static_cast<size_t>(j)];
    x.col(j) = (input.lo + u.col(j).array() * (input.hi - input.lo)).matrix();
  }
  return x;
}

InputSpace grow_box(const InputSpace& box, const Eigen::Ref<const Eigen::MatrixXd>& points, double coverage) {
  if (!(coverage > 0.0 && coverage <= 1.0)) throw Error("box growth: coverage must be in (0, 1], not " + std::to_string(coverage));
  if (points.cols() != static_cast<Eigen::Index>(box.size())) {
    throw Error("box growth: the points have " + std::to_string(points.cols()) + " columns, the box " +
                std::to_string(box.size()) + " inputs");
  }
  InputSpace grown = box;
  for (size_t j = 0; j < box.size(); ++j) {
    if (box[j].kind() == QuantityKind::angle) continue;
    std::vector<double> values;
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      const double value = points(i, static_cast<Eigen::Index>(j));
      if (std::isfinite(value)) values.push_back(value);
    }
    if (values.empty()) continue;
    // Nearest-rank quantiles (Hyndman & Fan 1996, definition 1) of all the points, so that growing
    // twice toward the same points changes nothing the second time.
    const auto rank = static_cast<std::ptrdiff_t>(std::max(1.0, std::ceil(coverage * static_cast<double>(values.size())))) - 1;
    std::nth_element(values.begin(), values.begin() + rank, values.end());
    grown[j].hi = std::max(box[j].hi, values[static_cast<size_t>(rank)]);
    std::nth_element(values.begin(), values.begin() + rank, values.end(), std::greater<>());
    grown[j].lo = std::min(box[j].lo, values[static_cast<size_t>(rank)]);
  }
  return grown;
}

}  // namespace mufric
