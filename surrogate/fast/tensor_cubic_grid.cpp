#include "surrogate/fast/tensor_cubic_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "common/error.hpp"

namespace mufric {
namespace {

constexpr int kMaximumInputs = TensorCubicGrid::kMaximumInputs;

struct Stencil {
  long long offset;            // of the first node, in doubles
  std::array<double, 4> weight;
};

// The four nodes around u ∈ [0, 1] on `cells` intervals and their cubic Lagrange weights.
Stencil stencil(double u, int cells, long long stride) {
  const double x = std::clamp(u, 0.0, 1.0) * cells;
  const int first = std::clamp(static_cast<int>(std::floor(x)) - 1, 0, cells - 3);
  const double r = x - first;  // in [0, 3] within the stencil
  Stencil s;
  s.offset = first * stride;
  s.weight = {-(r - 1.0) * (r - 2.0) * (r - 3.0) / 6.0, r * (r - 2.0) * (r - 3.0) / 2.0,
              -r * (r - 1.0) * (r - 3.0) / 2.0, r * (r - 1.0) * (r - 2.0) / 6.0};
  return s;
}

}  // namespace

long long TensorCubicGrid::node_count(const std::vector<int>& cells) {
  // A grid this large could not be stored anyway; the check keeps a hostile shape from overflowing.
  constexpr long long kMostNodes = 1LL << 40;
  long long count = 1;
  for (const int c : cells) {
    if (c < 0 || count > kMostNodes / (static_cast<long long>(c) + 1)) {
      throw Error("cubic grid: more than 2^40 nodes");
    }
    count *= c + 1;
  }
  return count;
}

Eigen::MatrixXd TensorCubicGrid::nodes(const std::vector<int>& cells) {
  const auto d = static_cast<Eigen::Index>(cells.size());
  const long long count = node_count(cells);
  Eigen::MatrixXd u(count, d);
  for (long long i = 0; i < count; ++i) {
    long long rest = i;
    for (Eigen::Index k = d - 1; k >= 0; --k) {
      const int per = cells[static_cast<size_t>(k)] + 1;
      u(i, k) = static_cast<double>(rest % per) / cells[static_cast<size_t>(k)];
      rest /= per;
    }
  }
  return u;
}

TensorCubicGrid::TensorCubicGrid(std::vector<int> cells, const Eigen::MatrixXd& values)
    : cells_(std::move(cells)), outputs_(static_cast<int>(values.cols())) {
  if (cells_.empty() || static_cast<int>(cells_.size()) > kMaximumInputs) {
    throw Error("cubic grid: " + std::to_string(cells_.size()) + " inputs (1 to " + std::to_string(kMaximumInputs) +
                " supported)");
  }
  for (const int c : cells_) {
    if (c < kMinimumCells) throw Error("cubic grid: " + std::to_string(c) + " cells along an input (at least 3)");
  }
  if (values.rows() != node_count(cells_) || outputs_ < 1) {
    throw Error("cubic grid: " + std::to_string(values.rows()) + " node values for " +
                std::to_string(node_count(cells_)) + " nodes");
  }
  if (!values.allFinite()) throw Error("cubic grid: non-finite node values");
  stride_.assign(cells_.size(), outputs_);
  for (int k = static_cast<int>(cells_.size()) - 2; k >= 0; --k) {
    stride_[static_cast<size_t>(k)] = stride_[static_cast<size_t>(k) + 1] * (cells_[static_cast<size_t>(k) + 1] + 1);
  }
  values_.resize(static_cast<size_t>(values.size()));
  for (Eigen::Index i = 0; i < values.rows(); ++i) {
    for (Eigen::Index o = 0; o < values.cols(); ++o) values_[static_cast<size_t>(i * outputs_ + o)] = values(i, o);
  }
}

namespace {

// The 3- and 4-input loops (p, v, T; and a fibre angle) with their trip counts known, so the
// compiler unrolls them. Weights multiply input by input and nodes are visited last input fastest,
// the generic loop's order, so the answers differ from its only by how the compiler fuses
// multiply-adds (rounding, ~1e-16), far inside any certified bound.
template <int Input, int Inputs, int Outputs>
void accumulate(const std::array<Stencil, kMaximumInputs>& s, const long long* stride, const double* node, double w,
                double* acc) {
  for (int a = 0; a < 4; ++a) {
    const double wa = Input == 0 ? s[0].weight[static_cast<size_t>(a)] : w * s[Input].weight[static_cast<size_t>(a)];
    if constexpr (Input + 1 == Inputs) {
      for (int o = 0; o < Outputs; ++o) acc[o] += wa * node[a * Outputs + o];
    } else {
      accumulate<Input + 1, Inputs, Outputs>(s, stride, node + a * stride[Input], wa, acc);
    }
  }
}

template <int Inputs, int Outputs>
void evaluate_unrolled(const std::array<Stencil, kMaximumInputs>& s, const long long* stride, const double* v,
                       double* out) {
  double acc[Outputs] = {};
  accumulate<0, Inputs, Outputs>(s, stride, v, 1.0, acc);
  for (int o = 0; o < Outputs; ++o) out[o] = acc[o];
}

}  // namespace

void TensorCubicGrid::evaluate(const double* u, double* out) const {
  const int d = inputs();
  std::array<Stencil, kMaximumInputs> s;
  long long base = 0;
  for (int k = 0; k < d; ++k) {
    s[static_cast<size_t>(k)] = stencil(u[k], cells_[static_cast<size_t>(k)], stride_[static_cast<size_t>(k)]);
    base += s[static_cast<size_t>(k)].offset;
  }
  const double* v = values_.data() + base;
  if (d == 3 && outputs_ == 2) {
    evaluate_unrolled<3, 2>(s, stride_.data(), v, out);
    return;
  }
  if (d == 4 && outputs_ == 2) {
    evaluate_unrolled<4, 2>(s, stride_.data(), v, out);
    return;
  }
  for (int o = 0; o < outputs_; ++o) out[o] = 0.0;
  const long long last = stride_[static_cast<size_t>(d - 1)];  // = outputs: the last input's nodes are adjacent
  const auto& w_last = s[static_cast<size_t>(d - 1)].weight;
  // Odometer over the first d − 1 inputs' stencils; the last input's four nodes in the inner loop.
  std::array<int, kMaximumInputs> digit{};
  for (;;) {
    double w = 1.0;
    long long offset = 0;
    for (int k = 0; k + 1 < d; ++k) {
      w *= s[static_cast<size_t>(k)].weight[static_cast<size_t>(digit[static_cast<size_t>(k)])];
      offset += digit[static_cast<size_t>(k)] * stride_[static_cast<size_t>(k)];
    }
    const double* node = v + offset;
    for (int j = 0; j < 4; ++j) {
      const double wj = w * w_last[static_cast<size_t>(j)];
      for (int o = 0; o < outputs_; ++o) out[o] += wj * node[j * last + o];
    }
    int k = d - 2;
    for (; k >= 0; --k) {
      if (++digit[static_cast<size_t>(k)] < 4) break;
      digit[static_cast<size_t>(k)] = 0;
    }
    if (k < 0) break;
  }
}

}  // namespace mufric
