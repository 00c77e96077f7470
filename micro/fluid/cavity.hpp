#pragma once
// The lid-driven cavity, the fluid solver's public benchmark (Ghia, Ghia & Shin, J. Comput. Phys.
// 48, 1982): the unit square, lid velocity 1, ρ = 1, η = 1/Re, steady; both centre lines sampled
// at Ghia's grid points with their published values (Tables I and II) where the Reynolds number
// is one they tabulate here (100).
#include <optional>
#include <vector>

#include "micro/fluid/navier_stokes.hpp"

namespace mufric::fluid {

struct CavityOptions {
  double reynolds = 100.0;
  int elements = 64;  // per side
  int degree = 2;
};

struct CenterlineSample {
  double position = 0.0;   // y on the vertical line x = 1/2, x on the horizontal line y = 1/2
  double velocity = 0.0;   // u on the vertical line, v on the horizontal line (per lid speed)
  std::optional<double> reference;  // Ghia et al.'s value, when tabulated
};

struct CavityResult {
  FluidStepReport report;
  std::vector<CenterlineSample> vertical;    // u(1/2, y), at Ghia's 17 points
  std::vector<CenterlineSample> horizontal;  // v(x, 1/2), at Ghia's 17 points
  // Largest |computed − reference| over both lines (per lid speed); empty without reference data.
  std::optional<double> max_deviation;
};

// Solves the cavity steady from rest (Newton, continuation in Re for Re > 100). Throws Error for
// options out of range.
CavityResult solve_cavity(const CavityOptions& options);

}  // namespace mufric::fluid
