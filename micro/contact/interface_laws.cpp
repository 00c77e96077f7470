#include "micro/contact/interface_laws.hpp"

#include <cmath>
#include <filesystem>

#include "common/error.hpp"
#include "common/registry.hpp"

namespace mufric::contact {
namespace {

void check_coefficient(double value, CoefficientRange range, const char* what) {
  if (!range.contains(value)) {
    throw Error(std::string("contact: the ") + what + " " + std::to_string(value) + " is outside [" +
                std::to_string(range.lo) + ", " + std::to_string(range.hi) + "]");
  }
}

// Below this (μ_a P / m k)ⁿ Childs' limit is μ_a P to 1e-13 relative (its next term is (1/2n) of it),
// and 1 − exp(−xⁿ) would lose its digits to the power 1/n − 1.
constexpr double kChildsCoulombRegime = 1e-13;

}  // namespace

CoefficientLaw::CoefficientLaw(LawCoefficients dry, LawCoefficients wetted) : dry_(dry), wetted_(wetted) {
  check_coefficient(dry_.adhesive_coefficient, kAdhesiveCoefficientRange, "adhesive coefficient");
  check_coefficient(dry_.shear_factor, kShearFactorRange, "shear factor");
  check_coefficient(wetted_.adhesive_coefficient, kAdhesiveCoefficientRange, "wetted adhesive coefficient");
  check_coefficient(wetted_.shear_factor, kShearFactorRange, "wetted shear factor");
}

bool CoefficientLaw::same_as(const InterfaceLaw& other) const {
  const auto* o = dynamic_cast<const CoefficientLaw*>(&other);
  return o != nullptr && name() == other.name() && dry_ == o->dry_ && wetted_ == o->wetted_;
}

CoulombLaw::CoulombLaw(double adhesive_coefficient, double wetted_adhesive_coefficient)
    : CoefficientLaw({.adhesive_coefficient = adhesive_coefficient}, {.adhesive_coefficient = wetted_adhesive_coefficient}) {}

SlipLimit CoulombLaw::slip_limit(const ContactPointState& point) const {
  const double mu = at(point).adhesive_coefficient;
  return {mu * point.pressure, mu};
}

ShearFactorLaw::ShearFactorLaw(double shear_factor, double wetted_shear_factor)
    : CoefficientLaw({.shear_factor = shear_factor}, {.shear_factor = wetted_shear_factor}) {}

SlipLimit ShearFactorLaw::slip_limit(const ContactPointState& point) const {
  // L = m k (1 − e^−x), x = μ₀ P/(m k); dL/dP = μ₀ e^−x.
  const double yield_shear = at(point).shear_factor * point.shear_strength;
  if (!(yield_shear > 0.0) || !(point.pressure > 0.0)) return {0.0, 0.0};
  const double x = kShearFactorOnsetCoefficient * point.pressure / yield_shear;
  return {-yield_shear * std::expm1(-x), kShearFactorOnsetCoefficient * std::exp(-x)};
}

ZorevLaw::ZorevLaw(LawCoefficients dry, LawCoefficients wetted) : CoefficientLaw(dry, wetted) {}

SlipLimit ZorevLaw::slip_limit(const ContactPointState& point) const {
  const LawCoefficients& c = at(point);
  const SlipLimit sliding{c.adhesive_coefficient * point.pressure, c.adhesive_coefficient};
  const double yield_shear = c.shear_factor * point.shear_strength;
  return yield_shear < sliding.shear ? SlipLimit{yield_shear, 0.0} : sliding;
}

TableLaw::TableLaw(std::shared_ptr<const AdhesionTable> table, double wetted_adhesive_coefficient)
    : CoefficientLaw({}, {.adhesive_coefficient = wetted_adhesive_coefficient}), table_(std::move(table)) {
  if (!table_) throw Error("contact: the table law needs its adhesion table");
}

bool TableLaw::same_as(const InterfaceLaw& other) const {
  const auto* o = dynamic_cast<const TableLaw*>(&other);
  return o != nullptr && CoefficientLaw::same_as(other) && table_->source() == o->table_->source();
}

SlipLimit TableLaw::slip_limit(const ContactPointState& point) const {
  if (point.wetted) {
    const double mu = wetted().adhesive_coefficient;
    return {mu * point.pressure, mu};
  }
  const AdhesionTable::Value mu = table_->at(point.pressure, point.sliding_velocity, point.temperature);
  return {mu.mu * point.pressure, mu.mu + point.pressure * mu.dmu_dpressure};
}

ChildsLaw::ChildsLaw(LawCoefficients dry, double exponent, LawCoefficients wetted)
    : CoefficientLaw(dry, wetted), exponent_(exponent) {
  check_coefficient(exponent_, kChildsExponentRange, "Childs exponent");
}

bool ChildsLaw::same_as(const InterfaceLaw& other) const {
  const auto* o = dynamic_cast<const ChildsLaw*>(&other);
  return o != nullptr && CoefficientLaw::same_as(other) && exponent_ == o->exponent_;
}

SlipLimit ChildsLaw::slip_limit(const ContactPointState& point) const {
  // L = m k a^(1/n), a = 1 − exp(−xⁿ), x = μ_a P/(m k); dL/dP = μ_a a^(1/n − 1) exp(−xⁿ) xⁿ⁻¹.
  const LawCoefficients& c = at(point);
  const double yield_shear = c.shear_factor * point.shear_strength;
  const double sliding = c.adhesive_coefficient * point.pressure;
  if (!(yield_shear > 0.0) || !(sliding > 0.0)) return {0.0, 0.0};  // no shear either way: τ ≤ min of the two
  const double n = exponent_;
  const double x = sliding / yield_shear;
  const double xn = std::pow(x, n);
  if (xn < kChildsCoulombRegime) return {sliding, c.adhesive_coefficient};
  const double a = -std::expm1(-xn);
  return {yield_shear * std::pow(a, 1.0 / n),
          c.adhesive_coefficient * std::pow(a, 1.0 / n - 1.0) * std::exp(-xn) * xn / x};
}

// ---- the registry -------------------------------------------------------------------------------

namespace {

double read_adhesive_coefficient(LawKeys& keys) {
  return keys.required_number("adhesive_coefficient", kAdhesiveCoefficientRange.lo, kAdhesiveCoefficientRange.hi,
                              "the interfacial mu_a, e.g. 0.1");
}
double read_shear_factor(LawKeys& keys) {
  return keys.required_number("shear_factor", kShearFactorRange.lo, kShearFactorRange.hi, "m in tau = m k, 0 to 1, e.g. 0.5");
}
LawCoefficients read_wetted(LawKeys& keys, bool adhesive, bool shear) {
  LawCoefficients c = kDefaultWettedCoefficients;
  if (adhesive) {
    c.adhesive_coefficient = keys.number("wetted.adhesive_coefficient", c.adhesive_coefficient,
                                         kAdhesiveCoefficientRange.lo, kAdhesiveCoefficientRange.hi);
  }
  if (shear) c.shear_factor = keys.number("wetted.shear_factor", c.shear_factor, kShearFactorRange.lo, kShearFactorRange.hi);
  return c;
}

std::shared_ptr<const InterfaceLaw> read_table_law(LawKeys& keys) {
  const std::string path = keys.required_file(
      "table", "a CSV of contact_pressure, sliding_velocity, temperature and mu_a over a full grid");
  std::shared_ptr<const AdhesionTable> table;
  try {
    table = std::make_shared<const AdhesionTable>(AdhesionTable::read(path));
  } catch (const Error& e) {
    keys.fail("table", e.what());
  }
  return std::make_shared<TableLaw>(table, read_wetted(keys, true, false).adhesive_coefficient);
}

}  // namespace

const std::vector<InterfaceLawEntry>& interface_laws() {
  static const std::vector<InterfaceLawEntry> laws = {
      {"frictionless", "no interfacial shear: mu from ploughing alone (seed 000's model)", {},
       [](LawKeys&) -> std::shared_ptr<const InterfaceLaw> { return std::make_shared<FrictionlessLaw>(); }},
      {"coulomb", "|tau| <= mu_a P", {"adhesive_coefficient", "wetted.adhesive_coefficient"},
       [](LawKeys& keys) -> std::shared_ptr<const InterfaceLaw> {
         const double mu = read_adhesive_coefficient(keys);
         return std::make_shared<CoulombLaw>(mu, read_wetted(keys, true, false).adhesive_coefficient);
       }},
      {"shear-factor", "|tau| <= m k, k the chip's shear yield stress", {"shear_factor", "wetted.shear_factor"},
       [](LawKeys& keys) -> std::shared_ptr<const InterfaceLaw> {
         const double m = read_shear_factor(keys);
         return std::make_shared<ShearFactorLaw>(m, read_wetted(keys, false, true).shear_factor);
       }},
      {"zorev", "|tau| <= min(mu_a P, m k)",
       {"adhesive_coefficient", "shear_factor", "wetted.adhesive_coefficient", "wetted.shear_factor"},
       [](LawKeys& keys) -> std::shared_ptr<const InterfaceLaw> {
         const LawCoefficients dry{read_adhesive_coefficient(keys), read_shear_factor(keys)};
         return std::make_shared<ZorevLaw>(dry, read_wetted(keys, true, true));
       }},
      {"table", "|tau| <= mu_a(P, v, T) P from a CSV table", {"table", "wetted.adhesive_coefficient"}, read_table_law},
      {"childs", "|tau| <= m k [1 - exp(-(mu_a P / m k)^n)]^(1/n), a smooth Zorev",
       {"adhesive_coefficient", "shear_factor", "childs_exponent", "wetted.adhesive_coefficient", "wetted.shear_factor"},
       [](LawKeys& keys) -> std::shared_ptr<const InterfaceLaw> {
         const LawCoefficients dry{read_adhesive_coefficient(keys), read_shear_factor(keys)};
         const double n = keys.required_number("childs_exponent", kChildsExponentRange.lo, kChildsExponentRange.hi,
                                               "n, the sharpness of the turn from mu_a P to m k, e.g. 1");
         return std::make_shared<ChildsLaw>(dry, n, read_wetted(keys, true, true));
       }},
  };
  return laws;
}

const InterfaceLawEntry* find_interface_law(std::string_view name) { return find_entry(interface_laws(), name); }

std::string interface_law_names() { return entry_names(interface_laws()); }

// ---- sampled point states -----------------------------------------------------------------------

SampledPointStates::SampledPointStates(size_t points, double sliding_velocity)
    : points_(points), sliding_velocity_(sliding_velocity) {}

ContactPointState SampledPointStates::state(size_t point) const {
  ContactPointState s;
  if (!shear_strength_.empty()) s.shear_strength = shear_strength_[point];
  if (!temperature_.empty()) s.temperature = temperature_[point];
  s.sliding_velocity = sliding_velocity_;
  s.wetted = !wetted_.empty() && wetted_[point] != 0;
  return s;
}

std::optional<std::string> SampledPointStates::missing(const PointStateNeeds& needs) const {
  if (needs.shear_strength && shear_strength_.empty()) return "the chip's shear yield stress at the contact (set_shear_strength)";
  if (needs.temperature && temperature_.empty()) return "the chip's temperature at the contact (set_temperature)";
  return std::nullopt;
}

void SampledPointStates::check_size(size_t given, const char* what) const {
  if (given != points_) {
    throw Error("contact: " + std::to_string(given) + " " + what + " for " + std::to_string(points_) + " surface points");
  }
}

void SampledPointStates::set_shear_strength(std::vector<double> k) {
  check_size(k.size(), "shear strengths");
  shear_strength_ = std::move(k);
}

void SampledPointStates::set_temperature(std::vector<double> temperature) {
  check_size(temperature.size(), "temperatures");
  temperature_ = std::move(temperature);
}

void SampledPointStates::set_wetted(std::vector<char> wetted) {
  if (!wetted.empty()) check_size(wetted.size(), "wetted flags");
  wetted_ = std::move(wetted);
}

}  // namespace mufric::contact
