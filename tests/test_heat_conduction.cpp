// Heat conduction in the chip against closed forms: a slab held at zero on one face and insulated on
// the others, released from a uniform temperature, cools by the Fourier series of Carslaw & Jaeger
// (Conduction of Heat in Solids, 1959, §3.3); a slab stretched by s through its thickness cools s
// times slower in reference time (the pulled-back conductivity J C⁻¹ k); heat released away from the
// held face is kept (energy balance).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "micro/solid/heat_conduction.hpp"

namespace mufric::solid {
namespace {

using numerics::Side;

using spline::Points2;
using spline::SplineBasis;
using spline::SplineSurface;

// The unit square, degree 2, `spans_y` spans through the thickness (y), two along x.
SplineSurface slab(int spans_y) {
  Points2 p(4, 2);
  p << 0, 0, 1, 0, 0, 1, 1, 1;
  SplineSurface s(SplineBasis::open_uniform(1, 1, 0, 1), SplineBasis::open_uniform(1, 1, 0, 1), p);
  return s.elevated_u().elevated_v().subdivided(2, spans_y);
}

// Mean excess temperature of a slab of unit thickness and diffusivity, held at 0 at y = 0, insulated
// at y = 1, from a uniform 1 at t = 0: Σ 8/((2n+1)²π²) exp(−((2n+1)π/2)² t).
double slab_mean(double t) {
  double sum = 0.0;
  for (int n = 0; n < 200; ++n) {
    const double m = (2 * n + 1) * std::numbers::pi;
    sum += 8.0 / (m * m) * std::exp(-0.25 * m * m * t);
  }
  return sum;
}

// Releases the slab (stretched by `stretch` through its thickness) from a uniform unit temperature
// and returns its mean temperature at each of `times` (reference time).
std::vector<double> cool(double stretch, const std::vector<double>& times) {
  const IgaSpace space(slab(24));
  HeatConduction heat(space, {.conductivity = 1.0, .density = 1.0, .specific_heat = 1.0,
                              .held_side = Side::bottom, .held_temperature = 0.0});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(space.dof_count());
  for (int a = 0; a < space.node_count(); ++a) u(2 * a + 1) = (stretch - 1.0) * space.node_position(a).y();
  std::vector<MaterialState> states(space.quadrature().size());
  for (auto& s : states) s.temperature = 1.0;  // the heat of an (adiabatic) step, released at once
  std::string reason;
  const double dt = 2e-4;
  EXPECT_TRUE(heat.step(u, 1e-12, states, reason)) << reason;  // the pulse, hardly conducted yet
  std::vector<double> means;
  double t = 0.0;
  for (double until : times) {
    for (; t < until - 1e-12; t += dt) {
      EXPECT_TRUE(heat.step(u, dt, states, reason)) << reason;
    }
    means.push_back(heat.heat_content());  // ρc = 1 over a unit reference area: the mean
  }
  return means;
}

TEST(HeatConduction, SlabCoolsAsTheFourierSeries) {
  const std::vector<double> times = {0.05, 0.2, 0.5};
  const auto means = cool(1.0, times);
  for (size_t k = 0; k < times.size(); ++k) {
    // Backward Euler with dt = 2e-4: first order, ~λ dt / 2 ≈ 0.03 % per unit of λ t; 0.5 % covers it.
    EXPECT_NEAR(means[k], slab_mean(times[k]), 5e-3 * slab_mean(times[k])) << "t = " << times[k];
  }
}

TEST(HeatConduction, StretchedSlabCoolsSlowerByTheStretch) {
  const double s = 1.6;
  const std::vector<double> times = {0.08, 0.32};
  const auto means = cool(s, times);
  for (size_t k = 0; k < times.size(); ++k) {
    EXPECT_NEAR(means[k], slab_mean(times[k] / s), 5e-3 * slab_mean(times[k] / s)) << "t = " << times[k];
  }
}

TEST(HeatConduction, HeatIsConservedBeforeItReachesTheHeldFace) {
  // Heat released in the top layer, one step far too short (diffusion length 0.01) to reach the held
  // bottom face 0.8 below: the heat content rises by exactly the heat released.
  const IgaSpace space(slab(24));
  HeatConduction heat(space, {.conductivity = 1.0, .density = 1.0, .specific_heat = 1.0,
                              .held_side = Side::bottom, .held_temperature = 0.0});
  std::vector<MaterialState> states(space.quadrature().size());
  double added = 0.0;
  for (size_t q = 0; q < states.size(); ++q) {
    const bool top_layer = space.quadrature()[q].position.y() > 0.8;
    states[q].temperature = top_layer ? 2.0 : 0.0;
    added += top_layer ? 2.0 * space.quadrature()[q].weight : 0.0;
  }
  std::string reason;
  ASSERT_TRUE(heat.step(Eigen::VectorXd::Zero(space.dof_count()), 1e-4, states, reason)) << reason;
  EXPECT_NEAR(heat.heat_content(), added, 1e-9 * added);
}

}  // namespace
}  // namespace mufric::solid
