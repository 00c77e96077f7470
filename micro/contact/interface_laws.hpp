#pragma once
// The registered interface laws (scene key contact.law). Each gives the slip limit of one contact
// point; MortarContact regularises stick with a tangential penalty and returns to the limit in slip
// (Wriggers, Computational Contact Mechanics, 2nd ed. 2006, §5.2.2; Laursen 2002 §5.3).
//
// A contact spot the lubricant reaches (wetted) shears through a boundary film instead of the bare
// metal junction: its law keeps its kind but takes the wetted coefficients — μ_a for Coulomb, Zorev,
// Childs and the table (a wetted spot's μ_a is the film's constant, the table being the dry
// junction's), m for shear-factor, Zorev and Childs (Williams & Tabor 1977, Wear 43:275, and Williams
// 1977, J. Mech. Eng. Sci. 19:202: cutting fluids act by reaching the junctions through capillaries
// and forming boundary films on them).
#include <memory>

#include "micro/contact/adhesion_table.hpp"
#include "micro/contact/interface_law.hpp"

namespace mufric::contact {

inline constexpr CoefficientRange kAdhesiveCoefficientRange{0.0, 5.0};  // μ_a
inline constexpr CoefficientRange kShearFactorRange{0.0, 1.0};          // m: τ = m k, at most the yield shear
// Childs' n: 1 is the exponential blend; at 20 the blend is within 2.3 % of Zorev's corner
// ((1 − 1/e)^(1/20) = 0.977 of m k there).
inline constexpr CoefficientRange kChildsExponentRange{0.5, 20.0};

// A straight cutting oil between AISI 4140 and a TiN-coated carbide pin brings μ to about 0.1,
// independent of the sliding velocity, at ~3 GPa (dry: falling with the velocity to about 0.2) —
// Claudin, Mondelin, Rech & Fromentin 2010, Int. J. Mach. Tools Manuf. 50:681; the boundary-lubrication
// range of Bowden & Tabor (The Friction and Lubrication of Solids, 1950) brackets it.
inline constexpr double kDefaultWettedAdhesiveCoefficient = 0.1;
// Lubricated metal forming's friction factor, m ≈ 0.05–0.3 by ring compression (Kobayashi, Oh & Altan,
// Metal Forming and the Finite-Element Method, 1989, sec. 5.4; Male & Cockcroft 1964): 0.2 is that of
// a lubricated steel.
inline constexpr double kDefaultWettedShearFactor = 0.2;

// A law's coefficients at one kind of spot: μ_a and m (each law uses those it names).
struct LawCoefficients {
  double adhesive_coefficient = 0.0;  // μ_a
  double shear_factor = 0.0;          // m
  bool operator==(const LawCoefficients&) const = default;
};
inline constexpr LawCoefficients kDefaultWettedCoefficients{kDefaultWettedAdhesiveCoefficient, kDefaultWettedShearFactor};

// Seed 000's model: no interfacial shear, μ from ploughing alone. The default.
class FrictionlessLaw final : public InterfaceLaw {
 public:
  std::string_view name() const override { return "frictionless"; }
  bool frictional() const override { return false; }
  SlipLimit slip_limit(const ContactPointState&) const override { return {}; }
};

// Base of the laws with coefficients at dry and at wetted spots.
class CoefficientLaw : public InterfaceLaw {
 public:
  const LawCoefficients& dry() const { return dry_; }
  const LawCoefficients& wetted() const { return wetted_; }
  bool same_as(const InterfaceLaw& other) const override;

 protected:
  CoefficientLaw(LawCoefficients dry, LawCoefficients wetted);
  const LawCoefficients& at(const ContactPointState& point) const { return point.wetted ? wetted_ : dry_; }

 private:
  LawCoefficients dry_, wetted_;
};

// |τ| ≤ μ_a P (Coulomb).
class CoulombLaw final : public CoefficientLaw {
 public:
  explicit CoulombLaw(double adhesive_coefficient, double wetted_adhesive_coefficient = kDefaultWettedAdhesiveCoefficient);
  std::string_view name() const override { return "coulomb"; }
  SlipLimit slip_limit(const ContactPointState& point) const override;
};

// |τ| ≤ m k, k the chip's shear yield stress at the point (Johnson–Cook / √3), reached smoothly from
// an opening contact point: m k [1 − exp(−μ₀ P/(m k))] with μ₀ = kShearFactorOnsetCoefficient, i.e.
// Childs' smooth law (Childs 2006, Wear 260:310) with n = 1 and a steep Coulomb onset. Taken as
// written (m k at any P > 0, nothing at P = 0), the limit jumps where an asperity's contact opens or
// closes, and Newton cut back 883 times at the default point without finishing (issue 63); with the
// onset it is m k to within e^−20 (2e-9) wherever P ≥ m k, which is every point carrying load.
inline constexpr double kShearFactorOnsetCoefficient = 20.0;
class ShearFactorLaw final : public CoefficientLaw {
 public:
  explicit ShearFactorLaw(double shear_factor, double wetted_shear_factor = kDefaultWettedShearFactor);
  std::string_view name() const override { return "shear-factor"; }
  PointStateNeeds needs() const override { return {.shear_strength = true}; }
  SlipLimit slip_limit(const ContactPointState& point) const override;
};

// |τ| ≤ min(μ_a P, m k): sliding where the pressure is low, sticking to the yield shear where it is
// high (Zorev 1963, the chip–tool friction model of cutting codes).
class ZorevLaw final : public CoefficientLaw {
 public:
  explicit ZorevLaw(LawCoefficients dry, LawCoefficients wetted = kDefaultWettedCoefficients);
  std::string_view name() const override { return "zorev"; }
  PointStateNeeds needs() const override { return {.shear_strength = true}; }
  SlipLimit slip_limit(const ContactPointState& point) const override;
};

// |τ| ≤ μ_a(P, v, T) P with μ_a from an AdhesionTable at the point's pressure, the sliding velocity
// and the chip's temperature there; a wetted spot takes the constant wetted μ_a.
class TableLaw final : public CoefficientLaw {
 public:
  explicit TableLaw(std::shared_ptr<const AdhesionTable> table,
                    double wetted_adhesive_coefficient = kDefaultWettedAdhesiveCoefficient);
  std::string_view name() const override { return "table"; }
  PointStateNeeds needs() const override { return {.temperature = true}; }
  SlipLimit slip_limit(const ContactPointState& point) const override;
  bool same_as(const InterfaceLaw& other) const override;
  const AdhesionTable& table() const { return *table_; }

 private:
  std::shared_ptr<const AdhesionTable> table_;
};

// Childs' smooth Zorev: |τ| ≤ m k [1 − exp(−(μ_a P / (m k))ⁿ)]^(1/n) (Childs 2006, "Friction
// modelling in metal cutting", Wear 260:310). Coulomb's μ_a P at low pressure, m k at high, with one smooth turn between them whose
// sharpness n sets (n → ∞ is Zorev's corner). Its slope in P is continuous, so Newton does not
// chatter between branches as at Zorev's corner, and its three coefficients are what a calibration
// against tribometer data fits: μ_a the sliding part, m the sticking part, n the transition.
class ChildsLaw final : public CoefficientLaw {
 public:
  ChildsLaw(LawCoefficients dry, double exponent, LawCoefficients wetted = kDefaultWettedCoefficients);
  std::string_view name() const override { return "childs"; }
  PointStateNeeds needs() const override { return {.shear_strength = true}; }
  SlipLimit slip_limit(const ContactPointState& point) const override;
  bool same_as(const InterfaceLaw& other) const override;
  double exponent() const { return exponent_; }

 private:
  double exponent_;
};

}  // namespace mufric::contact
