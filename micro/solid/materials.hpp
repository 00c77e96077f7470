#pragma once
// Constitutive models of the chip. A material maps the displacement gradient H = ∂u/∂X at a
// quadrature point (2×2, plane problems) and its state at the start of the step to the stress S
// work-conjugate to ∇δu (σ for small strain, the first Piola–Kirchhoff P for finite strain), the
// exact tangent ∂S/∂H and the state at the end of the step.
#include <array>
#include <memory>
#include <string>

#include <Eigen/Dense>

namespace mufric::solid {

// History carried per quadrature point (unused fields stay at their initial values).
struct MaterialState {
  // Inverse plastic right Cauchy–Green tensor Cp⁻¹: in-plane xx, xy, yy and out-of-plane zz.
  std::array<double, 4> plastic_metric_inverse{1.0, 0.0, 1.0, 1.0};
  double equivalent_plastic_strain = 0.0;
  double temperature = 293.15;  // K
  double yield_stress = 0.0;    // Pa, at the end of the last step (diagnostic)
  double plastic_strain_rate = 0.0;  // 1/s, over the last step: the next return map's first guess
};

struct StressResponse {
  Eigen::Matrix2d stress;   // S_ij
  Eigen::Matrix4d tangent;  // ∂S_ij/∂H_kl at row 2i+j, column 2k+l (when requested)
  MaterialState state;      // at the end of the step
  bool ok = true;           // false: the update failed (reason says why); never NaN
  std::string reason;
};

class Material {
 public:
  virtual ~Material() = default;
  // dt: the step's length (s), for rates; quasi-static runs pass their pseudo-time step. Without
  // `with_tangent` the response's tangent is left unset (a residual evaluation needs only S). The
  // tangent has major symmetry (∂S_ij/∂H_kl = ∂S_kl/∂H_ij: hyperelastic and associative models),
  // which the assembly relies on. `iterate`, when not null, is the state this point reached at the
  // previous Newton iterate of the same step: a first guess for the update's own iteration.
  virtual StressResponse update(const Eigen::Matrix2d& displacement_gradient, const MaterialState& start, double dt,
                                bool with_tangent, const MaterialState* iterate) const = 0;
  virtual double density() const = 0;  // kg/m³ (reference configuration)
  virtual bool finite_strain() const = 0;
  // k, Pa: the shear stress at which the material yields in the state `at` (von Mises: σ_y/√3); an
  // elastic material never does (+∞).
  virtual double shear_yield_stress(const MaterialState& at) const;
};

enum class PlaneKind { strain, stress };

// Small-strain isotropic linear elasticity (Hooke), plane strain or plane stress.
class LinearElastic final : public Material {
 public:
  LinearElastic(double youngs_modulus, double poisson_ratio, double density, PlaneKind kind = PlaneKind::strain);
  StressResponse update(const Eigen::Matrix2d& h, const MaterialState& start, double dt, bool with_tangent,
                        const MaterialState* iterate) const override;
  double density() const override { return density_; }
  bool finite_strain() const override { return false; }
  // Strain energy density ½ σ:ε (for energy checks).
  double energy_density(const Eigen::Matrix2d& h) const;

 private:
  double lambda_, mu_, density_;
};

// Johnson–Cook parameters, seed 000 Table 1 (temperatures there read as °C: 20 °C transition,
// 1500 °C melting, which is where steels melt; stored here in K).
struct JohnsonCookParameters {
  double youngs_modulus = 205e9;           // Pa
  double poisson_ratio = 0.29;
  double density = 7800.0;                 // kg/m³
  double a = 288e6;                        // Pa
  double b = 695e6;                        // Pa
  double c = 0.034;
  double n = 0.2835;
  double m = 1.3558;
  double reference_strain_rate = 0.004;    // 1/s, ε̇0
  double transition_temperature = 293.15;  // K (20 °C)
  double melting_temperature = 1773.15;    // K (1500 °C)
  double specific_heat = 450.0;            // J/(kg K)
  double heat_fraction = 0.9;              // share of plastic work turned into heat (Taylor–Quinney)
  bool operator==(const JohnsonCookParameters&) const = default;
};

// Yield stress of eq. (5)–(6) of seed 000. The rate factor is 1 + C ln(max(ε̇/ε̇0, 1)): the log
// term never lowers the yield stress below its ε̇0 value.
double johnson_cook_yield_stress(const JohnsonCookParameters& p, double plastic_strain, double plastic_strain_rate,
                                 double temperature);

// Finite-strain J2 plasticity with the multiplicative split F = Fe Fp, Hencky (logarithmic) elastic
// energy and Simo's return map in the exponential-map form (Simo, CMAME 99, 1992, Box 1: trial
// be = F Cp⁻¹ Fᵀ, radial return of the Kirchhoff stress on ½ ln be, be = exp(2εe)), plane strain,
// Johnson–Cook isotropic hardening solved by a bracketed Newton iteration (the JC hardening slope
// is infinite at zero plastic strain). Adiabatic heating after each converged update:
// Δθ = β σy Δε̄p / (ρ c); the yield stress of a step uses the temperature at its start (isothermal
// split). The tangent is the exact derivative of this update (forward-mode AD through the
// converged return map via the implicit-function theorem).
class J2JohnsonCook final : public Material {
 public:
  explicit J2JohnsonCook(JohnsonCookParameters parameters);
  StressResponse update(const Eigen::Matrix2d& h, const MaterialState& start, double dt, bool with_tangent,
                        const MaterialState* iterate) const override;
  double density() const override { return p_.density; }
  bool finite_strain() const override { return true; }
  // σ_JC(ε̄ᵖ, ε̇ᵖ, T)/√3 at the state's plastic strain, its last step's rate and its temperature.
  double shear_yield_stress(const MaterialState& at) const override;
  const JohnsonCookParameters& parameters() const { return p_; }
  double shear_modulus() const { return mu_; }
  double bulk_modulus() const { return kappa_; }

 private:
  // P and ∂P/∂F at F for the return map's converged Δγ (its σy and residual slope dr/dΔγ).
  void stress_and_tangent(const Eigen::Matrix2d& f, const MaterialState& start, double dgamma, double yield_stress,
                          double slope, StressResponse& out) const;
  JohnsonCookParameters p_;
  double mu_, kappa_;
};

}  // namespace mufric::solid
