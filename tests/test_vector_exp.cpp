// The dispatched vector exp against std::exp (glibc's scalar exp, < 1 ulp): every ISA this CPU runs
// stays within libmvec's documented 4 ulp, a value's exp does not depend on where it sits in the
// array (the padded tail), and the dispatcher uses the widest ISA unless told otherwise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "surrogate/core/vector_exp.hpp"

namespace mufric {
namespace {

constexpr double kUlpBound = 4.0;  // glibc manual, "Errors in Math Functions": libmvec exp ≤ 4 ulp

double ulps_between(double a, double b) {
  return std::abs(a - b) / (std::nextafter(std::abs(b), std::numeric_limits<double>::infinity()) - std::abs(b));
}

std::vector<double> exponents(size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> wide(-745.0, 709.0), kernel(-60.0, 0.0);
  std::vector<double> x(n);
  for (size_t i = 0; i < n; ++i) x[i] = i % 3 == 0 ? wide(rng) : kernel(rng);  // the GP's range is the second
  return x;
}

TEST(VectorExp, EveryIsaOfThisCpuIsWithinFourUlpOfTheScalarExp) {
  const std::vector<double> x = exponents(20'003, 1);  // not a multiple of any vector width
  for (const VectorIsa isa : {VectorIsa::sse2, VectorIsa::avx2, VectorIsa::avx512}) {
    if (!cpu_supports(isa)) {
      EXPECT_THROW(exp_in_place(isa, std::vector<double>(x).data(), 1), std::exception);
      continue;
    }
    std::vector<double> y = x;
    exp_in_place(isa, y.data(), static_cast<Eigen::Index>(y.size()));
    double worst = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
      const double exact = std::exp(x[i]);
      if (exact < std::numeric_limits<double>::min()) {  // subnormal results: their ulp is denorm_min
        EXPECT_LE(std::abs(y[i] - exact), kUlpBound * std::numeric_limits<double>::denorm_min()) << x[i];
        continue;
      }
      worst = std::max(worst, ulps_between(y[i], exact));
    }
    EXPECT_LE(worst, kUlpBound) << to_string(isa);
    std::vector<double> special = {0.0, -0.0, 1.0, -1000.0, 710.0, std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity()};
    exp_in_place(isa, special.data(), static_cast<Eigen::Index>(special.size()));
    EXPECT_EQ(special[0], 1.0);
    EXPECT_EQ(special[1], 1.0);
    EXPECT_NEAR(special[2], std::exp(1.0), 4e-16 * std::exp(1.0));
    EXPECT_EQ(special[3], 0.0);
    EXPECT_EQ(special[4], std::numeric_limits<double>::infinity());
    EXPECT_EQ(special[5], std::numeric_limits<double>::infinity());
    EXPECT_EQ(special[6], 0.0);
  }
}

TEST(VectorExp, AValuesExpDoesNotDependOnItsPositionInTheArray) {
  const std::vector<double> x = exponents(64, 2);
  for (const VectorIsa isa : {VectorIsa::sse2, VectorIsa::avx2, VectorIsa::avx512}) {
    if (!cpu_supports(isa)) continue;
    std::vector<double> whole = x;
    exp_in_place(isa, whole.data(), static_cast<Eigen::Index>(whole.size()));
    for (size_t offset = 0; offset < 9; ++offset) {  // every lane of the head and a tail of every length
      for (size_t length = 1; offset + length <= 17; ++length) {
        std::vector<double> part(x.begin() + static_cast<std::ptrdiff_t>(offset),
                                 x.begin() + static_cast<std::ptrdiff_t>(offset + length));
        exp_in_place(isa, part.data(), static_cast<Eigen::Index>(length));
        for (size_t k = 0; k < length; ++k) ASSERT_EQ(part[k], whole[offset + k]) << to_string(isa) << " " << offset;
      }
    }
  }
}

TEST(VectorExp, TheDispatcherUsesTheIsaItSays) {
  EXPECT_TRUE(cpu_supports(widest_vector_isa()));
  const VectorIsa used = vector_isa_in_use();
  EXPECT_TRUE(cpu_supports(used));
  std::vector<double> a = exponents(1001, 3), b = a;
  exp_in_place(a.data(), static_cast<Eigen::Index>(a.size()));
  exp_in_place(used, b.data(), static_cast<Eigen::Index>(b.size()));
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace mufric
