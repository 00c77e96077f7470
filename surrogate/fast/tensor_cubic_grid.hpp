#pragma once
// Piecewise-cubic tensor-product interpolation on a uniform grid over the unit box: each input's
// four nearest nodes (the stencil shifted inward at the box's faces), Lagrange weights per input,
// their tensor product over the inputs. Error O(h⁴) per input for smooth data (Süli & Mayers,
// "An Introduction to Numerical Analysis", Thm 6.2); continuous, with jumps of the gradient of that
// order between cells. Local: 4^d nodes per evaluation, whatever the grid size.
#include <cstddef>
#include <vector>

#include <Eigen/Dense>

namespace mufric {

class TensorCubicGrid {
 public:
  // Fewest cells per input: four nodes make one cubic stencil.
  static constexpr int kMinimumCells = 3;
  // Inputs one grid may have: the tensor sum has 4^d terms (256 for four inputs).
  static constexpr int kMaximumInputs = 6;

  // cells[k] intervals along input k (nodes cells[k] + 1); values: one row per node in node_index
  // order, one column per output. Throws mufric::Error for a shape that does not fit.
  TensorCubicGrid(std::vector<int> cells, const Eigen::MatrixXd& values);

  // Unit-box coordinates of every node, one row each, in node_index order (the last input fastest).
  static Eigen::MatrixXd nodes(const std::vector<int>& cells);
  static long long node_count(const std::vector<int>& cells);

  // out[o] for each output o at a point u of the unit box (clamped to it), d coordinates.
  void evaluate(const double* u, double* out) const;

  int inputs() const { return static_cast<int>(cells_.size()); }
  int outputs() const { return outputs_; }
  const std::vector<int>& cells() const { return cells_; }
  // Node values, node-major with the outputs of a node side by side (what the file stores).
  const std::vector<double>& values() const { return values_; }
  std::size_t bytes() const { return values_.size() * sizeof(double); }

 private:
  std::vector<int> cells_;
  int outputs_ = 0;
  std::vector<long long> stride_;  // in doubles, per input
  std::vector<double> values_;
};

}  // namespace mufric
