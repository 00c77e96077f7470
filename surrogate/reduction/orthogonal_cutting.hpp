#pragma once
// From orthogonal cutting tests to the rake face: per cutting speed, the rake-face friction
// coefficient, the mean normal stress, the chip's sliding velocity and the interface temperature,
// each with its uncertainty by Monte Carlo, for `mufric calibrate` as measurements with uncertain
// conditions. Every step is the analysis of data/cirp2022_ti6al4v_tin (its README has the equations):
//   1. edge forces apart: at each speed each force is a line in the uncut chip thickness h,
//      F = F_edge + k h (Altintas, Manufacturing Automation 2012, sec. 2.6; Albrecht 1960);
//   2. μ by Merchant's force circle from the slopes (Merchant 1945, J. Appl. Phys. 16:267);
//   3. the shear angle from the chip ratio, the sliding velocity V/λh;
//   4. the contact length by Oxley's chip equilibrium (Oxley, The Mechanics of Machining 1989, ch. 4);
//   5. Oxley's mean interface temperature (Boothroyd's shear-zone partition, ψ = 0.9).
// The uncertainty: each measured mean drawn from a normal of its standard error, a force's errors
// scaled by its line's Birge ratio where it exceeds 1 (Birge 1932, Phys. Rev. 40:207), and the
// secondary zone's relative thickness δ (log-uniform) and the chip's conductivity and specific heat
// (uniform) over their ranges. The draws are NumPy's stream (common/numpy_random.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "common/numpy_random.hpp"

namespace mufric {

// A measured mean with the standard error of that mean, SI.
struct MeasuredMean {
  double mean = 0.0;
  double standard_error = 0.0;
};

// One condition of orthogonal cutting tests, SI: forces in N for the cut's width.
struct OrthogonalCut {
  double group = 0.0;                 // a key the tests are analysed apart by (e.g. inclination); 0 if none
  double cutting_speed = 0.0;         // m/s
  double uncut_chip_thickness = 0.0;  // m
  MeasuredMean cutting_force, feed_force, chip_ratio;
  std::string row_name;               // "FILE line N"
};

// A uniform range; low == high: a fixed value.
struct ValueRange {
  double low = 0.0, high = 0.0;
};

// What the analysis needs besides the tests (SI).
struct OrthogonalCutSetup {
  double rake_angle = 0.0;        // rad
  double cut_width = 0.0;         // m
  double density = 0.0;           // kg/m³, the work material's
  ValueRange conductivity;        // W/(m K), the chip's at the interface's temperature: uniform
  ValueRange specific_heat;       // J/(kg K), likewise
  double room_temperature = 0.0;  // K, the work material's before the cut
  // δ, the secondary zone's thickness over the chip's: log-uniform (the range pantale/OxleyPython
  // optimises it over).
  ValueRange secondary_zone_ratio{0.005, 0.2};
  int draws = 20000;
  std::uint32_t seed = 2026;
};

// A Monte Carlo mean and SD (n − 1).
struct McEstimate {
  double mean = 0.0, sd = 0.0;
};
McEstimate monte_carlo_estimate(const Eigen::ArrayXd& draws);

// The rake face at one cutting speed of one group, SI (temperatures in K).
struct RakeFaceEstimate {
  double group = 0.0;
  double cutting_speed = 0.0;
  std::vector<double> thicknesses;  // m, ascending: the h the lines were fitted through
  McEstimate mu, contact_pressure, sliding_velocity, temperature;
  McEstimate temperature_thinnest, temperature_thickest;  // at the smallest and the largest h
  McEstimate chip_ratio, shear_angle, contact_length_per_h, oxley_c_neq;
  McEstimate specific_cutting_force, specific_feed_force;  // the lines' slopes over the width, Pa
  McEstimate edge_cutting_force, edge_feed_force;          // the lines' intercepts, N
  double birge_cutting = 1.0, birge_feed = 1.0;            // the error scale used (≥ 1)
  int nonpositive_mu_draws = 0;                            // draws in the scatter's tail with μ ≤ 0 (kept)
  std::vector<std::string> rows;                           // the tests it comes from
};

// Every group in ascending order, every speed in it ascending, one stream of draws through all
// (the order of the analysis' first form, data/cirp2022_ti6al4v_tin/rake_face.py, which this replaced). Each speed needs at
// least two thicknesses; with two the line has no degree of freedom left and no Birge scale (1).
// Throws Error naming the speed and the rows when the tests cannot give a rake face.
std::vector<RakeFaceEstimate> rake_face_from_orthogonal_cuts(const std::vector<OrthogonalCut>& cuts,
                                                             const OrthogonalCutSetup& setup);

}  // namespace mufric
