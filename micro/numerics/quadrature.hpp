#pragma once
// Quadrature rules shared by the chip, the film and the contact layer.
#include <vector>

namespace mufric::numerics {

// Gauss–Legendre nodes and weights on [−1, 1] (Golub & Welsch 1969, via the symmetric Jacobi matrix).
void gauss_legendre(int count, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace mufric::numerics
