#include "micro/fluid/cavity.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/error.hpp"

namespace mufric::fluid {

namespace {

// Ghia, Ghia & Shin (1982), Re = 100: grid indices k of their 129-point grid (position k/128) and
// the centre-line velocities of Table I (u along x = 1/2) and Table II (v along y = 1/2).
constexpr std::array<int, 17> kGhiaVerticalIndex = {128, 125, 124, 123, 122, 109, 94, 79, 64, 58, 36, 22, 13, 9, 8, 7, 0};
constexpr std::array<double, 17> kGhiaU100 = {1.0, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581,
                                              -0.21090, -0.15662, -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.0};
constexpr std::array<int, 17> kGhiaHorizontalIndex = {128, 124, 123, 122, 121, 116, 110, 103, 64, 30, 29, 20, 12, 10, 9, 8, 0};
constexpr std::array<double, 17> kGhiaV100 = {0.0, -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454,
                                              0.17527, 0.17507, 0.16077, 0.12317, 0.10890, 0.10091, 0.09233, 0.0};
// Steady Newton from rest converges directly up to this Reynolds number; above it the solve is
// continued from Re = 100 in steps of this factor.
constexpr double kDirectReynolds = 100.0;
constexpr double kContinuationFactor = 2.0;

}  // namespace

CavityResult solve_cavity(const CavityOptions& options) {
  if (!(options.reynolds > 0.0) || options.reynolds > 1e4) throw Error("cavity: --reynolds must lie in (0, 10000]");
  if (options.elements < 4 || options.elements > 512) throw Error("cavity: --elements must lie in [4, 512]");
  if (options.degree < 1 || options.degree > 4) throw Error("cavity: --degree must lie in [1, 4]");
  FluidSpace space(rectangle_patch(options.degree, options.elements, options.elements, Eigen::Vector2d::Zero(),
                                   Eigen::Vector2d::Ones(), false));
  NavierStokesOptions ns;
  ns.fluid.density = 1.0;
  ns.pinned_pressure_node = 0;  // enclosed: the pressure is fixed up to a constant
  NavierStokes solver(std::move(space), ns);
  const BoundaryField wall = [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); };
  const BoundaryField lid = [](const Eigen::Vector2d&, double) { return Eigen::Vector2d(1.0, 0.0); };
  // The lid first, then the walls: the corner control points belong to the walls (no leak).
  solver.set_conditions({{Side::top, SideConditionKind::velocity, lid, {}, 0.0},
                         {Side::left, SideConditionKind::velocity, wall, {}, 0.0},
                         {Side::right, SideConditionKind::velocity, wall, {}, 0.0},
                         {Side::bottom, SideConditionKind::velocity, wall, {}, 0.0}});
  CavityResult result;
  for (double re = std::min(options.reynolds, kDirectReynolds);; re = std::min(re * kContinuationFactor, options.reynolds)) {
    solver.set_properties({1.0, 1.0 / re});
    result.report = solver.solve_steady();
    if (!result.report.converged || re >= options.reynolds) break;
  }
  if (!result.report.converged) return result;
  const bool tabulated = std::abs(options.reynolds - 100.0) < 1e-12;
  double deviation = 0.0;
  for (size_t k = 0; k < kGhiaVerticalIndex.size(); ++k) {
    const double y = kGhiaVerticalIndex[k] / 128.0;
    CenterlineSample s{y, solver.velocity_at(0.5, y).x(), std::nullopt};
    if (tabulated) s.reference = kGhiaU100[k], deviation = std::max(deviation, std::abs(s.velocity - kGhiaU100[k]));
    result.vertical.push_back(s);
  }
  for (size_t k = 0; k < kGhiaHorizontalIndex.size(); ++k) {
    const double x = kGhiaHorizontalIndex[k] / 128.0;
    CenterlineSample s{x, solver.velocity_at(x, 0.5).y(), std::nullopt};
    if (tabulated) s.reference = kGhiaV100[k], deviation = std::max(deviation, std::abs(s.velocity - kGhiaV100[k]));
    result.horizontal.push_back(s);
  }
  if (tabulated) result.max_deviation = deviation;
  return result;
}

}  // namespace mufric::fluid
