// Per-point status handling shared by every model: invalid points never poison a batch.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "common/error.hpp"
#include "gp_test_data.hpp"
#include "surrogate/laws/empirical_laws.hpp"
#include "surrogate/gp/gp_grids.hpp"

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

// μ = 0.1 + 0.01·v[m/min] + 0.001·p[MPa] at every angle, on seed 001's box (p ≤ 200 MPa).
MlrLaw linear_law() { return MlrLaw({{90.0, 0.1, 0.01, 0.001, -10.0, 10.0, 1.0}}, "test", MlrLaw::seed001_box()); }

QueryBatch at_400_mpa() {
  QueryBatch x(1, 3);
  x << 400e6, 10.0 / 60.0, std::numbers::pi / 2;  // p twice the box's top, v 10 m/min, 90°
  return x;
}

// Outside the box: raw is the law itself, clamp the law at the box's face (zero slope along the
// clamped input), refuse no answer; closed forms of the linear law.
TEST(FrictionModel, ExtrapolationPoliciesOutsideTheBox) {
  const MlrLaw law = linear_law();
  const QueryBatch x = at_400_mpa();
  EvaluationRequest what{.gradient = true};
  what.extrapolation = Extrapolation::raw;
  Evaluation e = law.evaluate(x, what);
  EXPECT_EQ(e.status[0], PointStatus::extrapolated);
  EXPECT_NEAR(e.mu(0), 0.1 + 0.1 + 0.4, 1e-12);
  EXPECT_NEAR(e.gradient(0, 0), 0.001 / 1e6, 1e-18);
  what.extrapolation = Extrapolation::clamp;
  e = law.evaluate(x, what);
  EXPECT_EQ(e.status[0], PointStatus::extrapolated);
  EXPECT_NEAR(e.mu(0), 0.1 + 0.1 + 0.2, 1e-12);
  EXPECT_EQ(e.gradient(0, 0), 0.0);
  EXPECT_NEAR(e.gradient(0, 1), 0.01 * 60.0, 1e-12);  // per m/s: v is inside the box
  what.extrapolation = Extrapolation::refuse;
  e = law.evaluate(x, what);
  EXPECT_EQ(e.status[0], PointStatus::out_of_box);
  EXPECT_TRUE(std::isnan(e.mu(0)) && std::isnan(e.gradient(0, 0)));
  // The model's own default: clamp unless the file says otherwise.
  EXPECT_EQ(law.default_extrapolation(), Extrapolation::clamp);
  EXPECT_NEAR(law.evaluate(x, {}).mu(0), 0.4, 1e-12);
  MlrLaw raw_by_default = linear_law();
  raw_by_default.set_default_extrapolation(Extrapolation::raw);
  EXPECT_NEAR(raw_by_default.evaluate(x, {}).mu(0), 0.6, 1e-12);
  EXPECT_THROW(extrapolation_from_string("nearest"), Error);
}

// μ and its interval stay in the model's physical range; the points clipped are counted.
TEST(FrictionModel, MuIsKeptInTheModelsRange) {
  MlrLaw law = linear_law();
  law.set_mu_range(0.0, 0.5);
  EvaluationRequest what{.ci_level = 0.95};
  what.extrapolation = Extrapolation::raw;
  const Evaluation e = law.evaluate(at_400_mpa(), what);
  EXPECT_EQ(e.mu(0), 0.5);
  EXPECT_EQ(e.hi(0), 0.5);
  EXPECT_EQ(e.range_clipped, 1);
  EXPECT_THROW(law.set_mu_range(0.5, 0.5), Error);
  EXPECT_THROW(law.set_mu_range(0.0, std::numeric_limits<double>::infinity()), Error);
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


// Clamped, a GP keeps the face's μ but its σ is the posterior RMS error of that μ at the real point,
// √(σ_raw² + (μ_raw − μ_face)²), computed here from two separate evaluations: the raw model at the
// point and the model at the face. It grows with the distance and meets the face's σ at the face —
// with and without a fast evaluator (which answers inside the box only).
TEST(FrictionModel, AClampedIntervalGrowsWithTheDistanceFromTheBox) {
  GaussianProcess gp = test::fixed_hyper_gp(120, 7, 1.0, {0.4, 0.6, 0.5}, 1e-3);
  for (const bool fast : {false, true}) {
    if (fast) {
      FastEvaluatorOptions o;
      o.check_points = 1000;
      gp.attach_fast_evaluator(std::make_shared<const FastEvaluator>(build_fast_evaluator(gp, o)));
    }
    const double face = 1300e6;
    QueryBatch x(4, 3), at_face(4, 3);
    const double pressures[] = {face * (1 + 1e-12), 1500e6, 3000e6, 10000e6};
    for (Eigen::Index i = 0; i < 4; ++i) {
      x.row(i) << pressures[i], 1.5, 700.0;
      at_face.row(i) << face, 1.5, 700.0;
    }
    EvaluationRequest clamp{.std = true, .ci_level = 0.95};
    clamp.extrapolation = Extrapolation::clamp;
    EvaluationRequest raw = clamp;
    raw.extrapolation = Extrapolation::raw;
    raw.mu_tolerance = 0.0;  // the exact model: the formula's terms without grid error
    const Evaluation c = gp.evaluate(x, clamp), r = gp.evaluate(x, raw), f = gp.evaluate(at_face, clamp);
    const double z = normal_quantile_two_sided(0.95);
    for (Eigen::Index i = 0; i < 4; ++i) {
      EXPECT_EQ(c.status[static_cast<size_t>(i)], PointStatus::extrapolated);
      EXPECT_EQ(c.mu(i), f.mu(i)) << i;  // the face's μ, to the bit
      EXPECT_NEAR(c.std(i), std::hypot(r.std(i), r.mu(i) - f.mu(i)), 1e-9) << i;
      EXPECT_GE(c.std(i), r.std(i) * (1 - 1e-12)) << i;
      EXPECT_NEAR(c.hi(i), std::min(c.mu(i) + z * c.std(i), gp.mu_max()), 1e-12) << i;  // the interval uses it
      EXPECT_NEAR(c.lo(i), std::max(c.mu(i) - z * c.std(i), gp.mu_min()), 1e-12) << i;
    }
    EXPECT_NEAR(c.std(0), f.std(0), 1e-6 * f.std(0) + 1e-9);  // continuous at the face
    EXPECT_LT(c.std(1), c.std(2));
    EXPECT_LT(c.std(2), c.std(3));
    EXPECT_GT(c.std(3), 10 * f.std(3));  // far out: the prior's width, not the face's
  }
}


// A fibre angle repeats every 180°: 270° and −90° lie in a 0°–90° box, 100° does not (issue 30).
TEST(FrictionModel, AnAngleIsInsideItsBoxModulo180Degrees) {
  const double deg = std::numbers::pi / 180.0;
  const InputSpec angle{"fibre_angle", "rad", 0.0, 90.0 * deg};
  EXPECT_TRUE(angle.contains(270.0 * deg));
  EXPECT_TRUE(angle.contains(-90.0 * deg));
  EXPECT_TRUE(angle.contains(180.0 * deg));
  EXPECT_FALSE(angle.contains(100.0 * deg));
  EXPECT_FALSE(angle.contains(-10.0 * deg));
  EXPECT_FALSE(angle.contains(std::nan("")));
  const InputSpec pressure{"contact_pressure", "Pa", 0.0, 90.0 * deg};  // not periodic
  EXPECT_FALSE(pressure.contains(270.0 * deg));
}

// Why a point is not OK names the input, the side and the value in human units; a response's message
// names the first unanswered point and counts the others.
TEST(FrictionModel, PointReasonsNameTheInputAndTheSide) {
  const InputSpace box = default_friction_box();
  const double inside[] = {800e6, 1.0, 700.0}, above[] = {10000e6, 1.0, 700.0}, below[] = {800e6, 0.1, 700.0},
               negative[] = {-5e6, 1.0, 700.0};
  EXPECT_EQ(point_reason(box, inside), "");
  EXPECT_EQ(point_reason(box, above), "contact_pressure: 1e+04MPa is above the box (300MPa to 1300MPa)");
  EXPECT_EQ(point_reason(box, below), "sliding_velocity: 6m/min is below the box (22.5m/min to 200m/min)");
  EXPECT_EQ(point_reason(box, negative), "contact_pressure: -5MPa is below 0MPa, the least a pressure can be");
  // Every input at fault is named (regression: a point outside in two inputs named one).
  const double two_outside[] = {10000e6, 0.1, 700.0};
  EXPECT_EQ(point_reason(box, two_outside), "contact_pressure: 1e+04MPa is above the box (300MPa to 1300MPa); "
                                            "sliding_velocity: 6m/min is below the box (22.5m/min to 200m/min)");
  QueryBatch x(3, 3);
  x.row(0) = Eigen::Map<const Eigen::RowVector3d>(inside);
  x.row(1) = Eigen::Map<const Eigen::RowVector3d>(negative);
  x.row(2) = Eigen::Map<const Eigen::RowVector3d>(above);
  const std::vector<PointStatus> status{PointStatus::ok, PointStatus::invalid_input, PointStatus::out_of_box};
  EXPECT_EQ(unanswered_points_message(box, x, status),
            "point 1 INVALID_INPUT: contact_pressure: -5MPa is below 0MPa, the least a pressure can be (and 1 more "
            "point without an answer)");
  EXPECT_EQ(unanswered_points_message(box, x, {PointStatus::ok, PointStatus::ok, PointStatus::extrapolated}), "");
  EXPECT_EQ(more_points_tail(0, false), "");
  EXPECT_EQ(more_points_tail(2, false), " (and 2 more points without an answer)");
  EXPECT_EQ(more_points_tail(1, true), " (and 1 more point outside the box)");
}

}  // namespace
}  // namespace mufric
