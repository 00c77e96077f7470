// Sampling plans: Sobol' against Joe & Kuo's published first points and the net property that
// defines the sequence; Latin hypercube strata; reproducibility; scaling into the box.
#include <gtest/gtest.h>

#include <set>

#include "common/error.hpp"
#include "surrogate/sampling.hpp"

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

}  // namespace
}  // namespace mufric
