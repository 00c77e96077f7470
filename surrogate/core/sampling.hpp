#pragma once
// Sampling plans over an input box: where the micro-model (or a law) is evaluated.
//   random          — independent uniform points (std::mt19937_64);
//   latin-hypercube — one point per stratum of every input (McKay, Beckman & Conover,
//                     Technometrics 21, 1979);
//   sobol           — the Sobol' low-discrepancy sequence with Joe & Kuo's direction numbers
//                     (boost::random::sobol), its all-zero first point skipped; a non-zero seed
//                     applies a random digital shift (XOR of each coordinate with a seeded random
//                     word), which keeps every (t, m, s)-net property of the sequence.
#include <cstdint>
#include <random>
#include <string>

#include <Eigen/Dense>

#include "common/h5_file.hpp"
#include "common/input_space.hpp"

namespace mufric {

enum class PlanDesign { random, latin_hypercube, sobol };

// "random", "lhs" / "latin-hypercube", "sobol"; throws Error naming the accepted names.
PlanDesign parse_plan_design(const std::string& name);
std::string plan_design_name(PlanDesign design);

// n points in [0, 1)^d.
Eigen::MatrixXd unit_plan(PlanDesign design, Eigen::Index n, Eigen::Index d, std::uint64_t seed);
// The same plan scaled into the box of `inputs` (SI), one row per point.
h5::RowMatrix plan_in_box(PlanDesign design, Eigen::Index n, const InputSpace& inputs, std::uint64_t seed);

// The box grown so that, per input and side, it covers the `coverage` quantile of the points
// (1: every point; 0.99 leaves the farthest 1 % of them out on each side, so that one spike of a
// meso code does not stretch the campaign). Never shrinks; growing again toward the same points
// changes nothing. Angles are periodic and keep their box. Points with a non-finite input are
// ignored. Throws Error if coverage is not in (0, 1] or the columns differ.
InputSpace grow_box(const InputSpace& box, const Eigen::Ref<const Eigen::MatrixXd>& points, double coverage);

// A Latin hypercube drawn from `rng` (for callers that keep drawing from the same generator).
Eigen::MatrixXd latin_hypercube(Eigen::Index n, Eigen::Index d, std::mt19937_64& rng);

}  // namespace mufric
