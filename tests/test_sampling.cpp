// Sampling plans: Sobol' against Joe & Kuo's published first points and the net property that
// defines the sequence; Latin hypercube strata; reproducibility; scaling into the box.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "common/error.hpp"
#include "surrogate/core/sampling.hpp"

namespace mufric {
namespace {

TEST(Sampling, SobolStartsWithJoeKuosPublishedPoints) {
  // Joe & Kuo, new-joe-kuo-6.21201, dimensions 1–3, points 1–6 (point 0 is the origin).
  const double expected[6][3] = {{0.5, 0.5, 0.5},       {0.75, 0.25, 0.25},   {0.25, 0.75, 0.75},
                                 {0.375, 0.375, 0.625}, {0.875, 0.875, 0.125}, {0.625, 0.125, 0.875}};
  const Eigen::MatrixXd u = unit_plan(PlanDesign::sobol, 6, 3, 0);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_DOUBLE_EQ(u(i, j), expected[i][j]) << "point " << i + 1 << ", dimension " << j + 1;
  }
}

// The first 2^m points of a Sobol' sequence (origin included) form a (0, m, 2)-net in dimensions
// 1 and 2: every box [a/2^k, (a+1)/2^k) × [b/2^(m−k), (b+1)/2^(m−k)) holds exactly one point. A
// digital shift keeps that property.
void expect_zero_m_two_net(const Eigen::MatrixXd& with_origin, int m) {
  const long long n = 1LL << m;
  for (int k = 0; k <= m; ++k) {
    std::set<std::pair<long long, long long>> boxes;
    for (long long i = 0; i < n; ++i) {
      boxes.emplace(static_cast<long long>(with_origin(i, 0) * (1LL << k)),
                    static_cast<long long>(with_origin(i, 1) * (1LL << (m - k))));
    }
    EXPECT_EQ(static_cast<long long>(boxes.size()), n) << "k = " << k;
  }
}

TEST(Sampling, SobolPointsFormANetAlsoWhenShifted) {
  const int m = 8;
  for (const std::uint64_t seed : {0ULL, 42ULL}) {
    const Eigen::MatrixXd u = unit_plan(PlanDesign::sobol, (1 << m) - 1, 2, seed);
    // The origin shifted by the same digital shift: the point the sequence skips.
    Eigen::MatrixXd all((1 << m), 2);
    all.topRows((1 << m) - 1) = u;
    if (seed == 0) {
      all.row((1 << m) - 1).setZero();
    } else {
      // 0 XOR shift = shift; shift = point1 XOR 0.5 in each coordinate (point 1 of the unshifted
      // sequence is 0.5 = the top bit).
      for (int j = 0; j < 2; ++j) {
        const double p1 = u(0, j);
        all((1 << m) - 1, j) = p1 >= 0.5 ? p1 - 0.5 : p1 + 0.5;
      }
    }
    expect_zero_m_two_net(all, m);
  }
}

TEST(Sampling, LatinHypercubeHitsEveryStratumOnceAndIsReproducible) {
  const Eigen::Index n = 37;
  const Eigen::MatrixXd u = unit_plan(PlanDesign::latin_hypercube, n, 3, 7);
  for (Eigen::Index j = 0; j < 3; ++j) {
    std::set<long long> strata;
    for (Eigen::Index i = 0; i < n; ++i) strata.insert(static_cast<long long>(u(i, j) * static_cast<double>(n)));
    EXPECT_EQ(static_cast<Eigen::Index>(strata.size()), n) << "input " << j;
  }
  EXPECT_EQ(u, unit_plan(PlanDesign::latin_hypercube, n, 3, 7));
  EXPECT_NE(u, unit_plan(PlanDesign::latin_hypercube, n, 3, 8));
}

TEST(Sampling, PlansLieInTheBoxAndNamesParse) {
  const InputSpace box = default_friction_box();
  for (const auto* name : {"random", "lhs", "latin-hypercube", "sobol"}) {
    const PlanDesign design = parse_plan_design(name);
    const h5::RowMatrix x = plan_in_box(design, 100, box, 3);
    for (Eigen::Index j = 0; j < x.cols(); ++j) {
      EXPECT_GE(x.col(j).minCoeff(), box[static_cast<size_t>(j)].lo) << name;
      EXPECT_LT(x.col(j).maxCoeff(), box[static_cast<size_t>(j)].hi) << name;
    }
    EXPECT_EQ(parse_plan_design(plan_design_name(design)), design);
  }
  EXPECT_THROW(parse_plan_design("halton"), Error);
  EXPECT_THROW(unit_plan(PlanDesign::random, 0, 3, 1), Error);
}

// grow_box against a sort of every column: coverage 1 reaches the extremes, coverage q the
// ceil(q n)-th value from each end; an angle keeps its box, the box never shrinks, NaN rows are
// ignored, and growing twice is growing once.
TEST(Sampling, GrowBoxCoversTheQuantileOfThePointsPerSide) {
  const InputSpace box = {{"contact_pressure", "Pa", 300e6, 1300e6}, {"sliding_velocity", "m/s", 0.375, 3.33},
                          {"fibre_angle", "rad", 0.0, 1.0}};
  std::mt19937_64 rng(3);
  std::normal_distribution<double> wide(800e6, 900e6), speed(1.5, 2.0), angle(0.5, 3.0);
  const Eigen::Index n = 200;
  Eigen::MatrixXd points(n + 1, 3);
  for (Eigen::Index i = 0; i < n; ++i) points.row(i) << wide(rng), std::abs(speed(rng)) + 0.5, angle(rng);
  points.row(n) << std::nan(""), 1e9, 0.2;  // a non-finite pressure: its other inputs still count
  for (const double coverage : {1.0, 0.9}) {
    const InputSpace grown = grow_box(box, points, coverage);
    for (Eigen::Index j = 0; j < 2; ++j) {
      std::vector<double> column;
      for (Eigen::Index i = 0; i <= n; ++i) {
        if (std::isfinite(points(i, j))) column.push_back(points(i, j));
      }
      std::sort(column.begin(), column.end());
      const auto k = static_cast<size_t>(std::ceil(coverage * static_cast<double>(column.size()))) - 1;
      EXPECT_EQ(grown[static_cast<size_t>(j)].hi, std::max(box[static_cast<size_t>(j)].hi, column[k])) << j << " " << coverage;
      EXPECT_EQ(grown[static_cast<size_t>(j)].lo, std::min(box[static_cast<size_t>(j)].lo, column[column.size() - 1 - k]))
          << j << " " << coverage;
    }
    EXPECT_EQ(grown[2].lo, 0.0);  // periodic
    EXPECT_EQ(grown[2].hi, 1.0);
    const InputSpace again = grow_box(grown, points, coverage);
    for (size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(again[j].lo, grown[j].lo);
      EXPECT_EQ(again[j].hi, grown[j].hi);
    }
  }
  EXPECT_EQ(grow_box(box, points, 1.0)[1].hi, 1e9);
  const Eigen::MatrixXd inside = Eigen::MatrixXd::Constant(4, 3, 0.5).array().rowwise() * Eigen::RowVector3d(1e9, 1.0, 1.0).array();
  EXPECT_EQ(grow_box(box, inside, 1.0)[0].lo, 300e6);  // never shrinks
  EXPECT_THROW(grow_box(box, points, 0.0), Error);
  EXPECT_THROW(grow_box(box, points.leftCols(2), 1.0), Error);
}

}  // namespace
}  // namespace mufric
