#pragma once
// Closed-form friction laws behind the same FrictionModel interface as the GP:
//  - Coulomb: a constant μ (today's meso-scale practice; the baseline mufric replaces).
//  - Seed 001 (Seward et al. 2022, eq. 5/17): μ = β0 + β1·v + β2·p per fibre angle, clamped to
//    [μmin, μmax] as in its Listing 1, with v in m/min and p in MPa as the paper tabulates them.
#include <string>
#include <vector>

#include "surrogate/core/friction_model.hpp"

namespace mufric {

class CoulombLaw final : public FrictionModel {
 public:
  // Inputs default to the seed-000 box (p, v, T); μ does not depend on them.
  explicit CoulombLaw(double mu, InputSpace inputs = default_friction_box());
  std::string_view kind() const override { return "coulomb"; }
  bool has_uncertainty() const override { return false; }
  void write(h5::Writer& out) const override;
  std::string summary() const override;
  double mu() const { return mu_; }
  static CoulombLaw read(const h5::Reader& in, InputSpace inputs);

 protected:
  void evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const override;

 private:
  double mu_;
};

// One row of seed 001's Table 2 or Table 4, in the paper's units.
struct MlrRow {
  double fibre_angle_deg;
  double beta0;             // 1
  double beta1_per_m_min;   // per (m/min) of sliding velocity
  double beta2_per_mpa;     // per MPa of contact pressure
  double mu_min, mu_max;    // clamp of Listing 1
  double r_squared;         // as published or as fitted
};

// Inputs: contact_pressure (Pa), sliding_velocity (m/s), fibre_angle (rad). Between tabulated angles
// the clamped μ of the two neighbours is interpolated linearly; angles are periodic with 180°
// (a unidirectional ply at θ and θ + 180° is the same ply).
class MlrLaw final : public FrictionModel {
 public:
  MlrLaw(std::vector<MlrRow> rows, std::string source, InputSpace inputs);
  std::string_view kind() const override { return "mlr"; }
  bool has_uncertainty() const override { return false; }
  void write(h5::Writer& out) const override;
  std::string summary() const override;
  const std::vector<MlrRow>& rows() const { return rows_; }
  static MlrLaw read(const h5::Reader& in, InputSpace inputs);

  // The validity box of seed 001's experiments: p 0–200 MPa (its Fig. 9), v 1–15 m/min, θ 0–180°.
  static InputSpace seed001_box();
  // Seed 001 Table 2 (apparent COF, ACOF) and Table 4 (adhesive COF, ADCOF). The clamp of
  // Listing 1 (μ ∈ [0.093755565, 0.322395506], given there for 90°) is the only one the paper
  // publishes; it is applied to every angle of both tables.
  static MlrLaw seed001_table2();
  static MlrLaw seed001_table4();

 protected:
  void evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const override;

 private:
  std::vector<MlrRow> rows_;  // sorted by angle, angles in [0, 180)
  std::string source_;
};

struct MlrFitReport {
  struct PerAngle {
    double fibre_angle_deg;
    long long samples;
    double r_squared;
  };
  std::vector<PerAngle> angles;
};

// Least-squares fit (Householder QR) of μ = β0 + β1·v + β2·p per fibre angle from a CSV with columns
// fibre_angle, contact_pressure, sliding_velocity (units in the header) and mu. The clamp per angle
// is the range of measured μ at that angle. Errors name the file and the offending angle.
MlrLaw fit_mlr_law(const std::string& csv_path, MlrFitReport* report = nullptr);

}  // namespace mufric
