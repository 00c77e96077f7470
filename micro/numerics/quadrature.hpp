#pragma once
// Quadrature rules shared by the chip, the film and the contact layer.
#include <vector>

namespace mufric::numerics {

// Gauss–Legendre nodes and weights on [−1, 1] (Golub & Welsch 1969, via the symmetric Jacobi matrix).
void gauss_legendre(int count, std::vector<double>& nodes, std::vector<double>& weights);

// One point of a patch's tensor Gauss–Legendre rule, in parameter space.
struct ElementPoint {
  double u = 0.0, v = 0.0;
  double weight = 0.0;               // parametric: the rule's weight times the span's area / 4
  double span_u = 0.0, span_v = 0.0; // the element's extent in u and v
  int element = 0;                   // eu + elements_u · ev
};
// The points of every knot-span element of a patch (breakpoints along u and v), the elements in
// order of v then u, each element's points in order of v then u, degree + 1 per direction.
std::vector<ElementPoint> element_gauss_points(const std::vector<double>& breaks_u, const std::vector<double>& breaks_v,
                                               int points_u, int points_v);

}  // namespace mufric::numerics
