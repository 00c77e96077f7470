#pragma once
// The four sides of a spline patch, named for the chip's and the film's orientation: the chip's
// loaded bottom Γ_B, its rough top, and the periodic ends.
namespace mufric::numerics {

enum class Side { bottom, top, left, right };  // v = lo, v = hi, u = lo, u = hi

}  // namespace mufric::numerics
