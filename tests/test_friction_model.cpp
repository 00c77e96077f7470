// Per-point status handling shared by every model: invalid points never poison a batch.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/error.hpp"
#include "surrogate/empirical_laws.hpp"

namespace mufric {
namespace {

TEST(FrictionModel, InvalidPointsGetNaNAndTheirStatusTheRestIsAnswered) {
  const CoulombLaw law(0.3);
  QueryBatch x(5, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  x << 800e6, 1.0, 700.0,                                     // inside the box
      nan, 1.0, 700.0,                                        // NaN pressure
      -1e6, 1.0, 700.0,                                       // negative pressure
      2000e6, 1.0, 700.0,                                     // outside the box
      800e6, std::numeric_limits<double>::infinity(), 700.0;  // infinite velocity
  const Evaluation e = law.evaluate(x, {.std = true, .ci_level = 0.95, .gradient = true});
  EXPECT_EQ(e.status[0], PointStatus::ok);
  EXPECT_EQ(e.status[1], PointStatus::invalid_input);
  EXPECT_EQ(e.status[2], PointStatus::invalid_input);
  EXPECT_EQ(e.status[3], PointStatus::extrapolated);
  EXPECT_EQ(e.status[4], PointStatus::invalid_input);
  EXPECT_EQ(e.mu(0), 0.3);
  EXPECT_EQ(e.mu(3), 0.3);
  EXPECT_TRUE(std::isnan(e.mu(1)) && std::isnan(e.std(2)) && std::isnan(e.lo(4)) && std::isnan(e.gradient(1, 0)));
}

TEST(FrictionModel, WrongNumberOfInputsAndBadLevelAreErrors) {
  const CoulombLaw law(0.3);
  EXPECT_THROW(law.evaluate(QueryBatch::Zero(2, 2), {}), Error);
  EXPECT_THROW(law.evaluate(QueryBatch::Constant(1, 3, 500.0), {.ci_level = 1.5}), Error);
}

TEST(FrictionModel, NormalQuantileMatchesTables) {
  EXPECT_NEAR(normal_quantile_two_sided(0.95), 1.959963984540054, 1e-12);
  EXPECT_NEAR(normal_quantile_two_sided(0.99), 2.5758293035489004, 1e-12);
  EXPECT_NEAR(normal_quantile_two_sided(0.6826894921370859), 1.0, 1e-10);
}

}  // namespace
}  // namespace mufric
