#pragma once
// The elastic mesh-update method (EMUM; Tezduyar et al., CMAME 94, 1992; Jacobian-based stiffening of
// Stein, Tezduyar & Benney, J. Appl. Mech. 70, 2003): the fluid's control net follows its moving
// boundaries as a linear-elastic body, solved for the increment on the current mesh, with the
// stiffness at each Gauss point scaled by (J_ref/J)^χ so that small elements deform less than large
// ones and the mesh stays valid under large boundary motion.
#include <string>
#include <utility>
#include <vector>

#include "micro/fluid/fluid_space.hpp"
#include "micro/numerics/linear_solver.hpp"

namespace mufric::fluid {

struct MeshUpdateOptions {
  double stiffening_exponent = 1.0;  // χ: 0 = plain linear elasticity
  double poisson_ratio = 0.3;        // of the fictitious mesh material
};

struct MeshMoveReport {
  bool ok = false;
  std::string reason;                // why not
  double min_relative_jacobian = 1.0;  // of the moved mesh (≤ 0: folded)
};

// Gives the space this displacement of its net if the mesh it makes is valid (min relative
// Jacobian > 0); otherwise leaves the space as it was and says why.
MeshMoveReport place_mesh(FluidSpace& space, const Eigen::VectorXd& displacement);

class MeshUpdate {
 public:
  explicit MeshUpdate(MeshUpdateOptions options = {});
  // Moves the space's net: the control points in `prescribed` move by the given increments, every
  // other one by the elastic solution; the space's displacement is updated only when the moved mesh
  // is valid (min relative Jacobian > 0).
  MeshMoveReport move(FluidSpace& space, const std::vector<std::pair<int, Eigen::Vector2d>>& prescribed);

 private:
  MeshUpdateOptions options_;
  numerics::LinearSolver solver_{numerics::LinearSolverKind::cholesky};
};

}  // namespace mufric::fluid
