#pragma once
// The interface law as a point kernel: what shear one contact point admits before it slips, given
// that point's state — as solid::Material is for the bulk's quadrature points, and as PetIGA and
// MFEM treat physics at a quadrature point. MortarContact owns the kinematics (gap, tangential
// offset, stick's penalty regularisation, the return map and its linearisation); a law answers only
// the slip limit |τ| ≤ τ_lim(state) and its slope in the pressure. A law says which parts of the
// state it needs, reads and checks its own scene keys, and is registered by name (interface_laws()):
// a new law is one class and one registry line (interface_laws.cpp).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mufric::contact {

// The range every reader and constructor holds a coefficient to (one source for both).
struct CoefficientRange {
  double lo, hi;
  bool contains(double x) const { return x >= lo && x <= hi; }
};

// The state of one contact point as a law sees it. The contact supplies the pressure; the rest comes
// from the PointStateProvider the contact's owner attaches (the chip beneath the point, the lubricant
// around it), as of the last accepted step: within a step the law's inputs are frozen, so a step's
// Newton iteration sees one law (the tangent's slope is in P alone).
// (No law uses the point's own slip rate: a rate-dependent law reads the scene's sliding velocity,
// as the table's v does. A law of the local slip rate would make the return map implicit in the slip;
// none of the laws the calibration needs asks for that.)
struct ContactPointState {
  double pressure = 0.0;          // P, Pa: the mortar pressure (> 0 where the law is asked)
  double shear_strength = 0.0;    // k, Pa: the chip's shear yield stress beneath the point
  double temperature = 0.0;       // T, K: the chip's temperature there
  double sliding_velocity = 0.0;  // |v|, m/s: the chip's speed along the tool
  bool wetted = false;            // the lubricant reaches the spot (the law takes its wetted coefficients)
};

// What a law needs from the provider beyond the pressure (the sliding velocity and wetted flags are
// always given: the provider knows them from the scene).
struct PointStateNeeds {
  bool shear_strength = false;
  bool temperature = false;
  bool any() const { return shear_strength || temperature; }
};

// The admissible shear at a point in contact, Pa, and its derivative in the point's pressure (for the
// tangent of slip; 0 where the limit does not depend on P within a step, such as m k).
struct SlipLimit {
  double shear = 0.0;
  double dshear_dpressure = 0.0;
};

class InterfaceLaw {
 public:
  virtual ~InterfaceLaw() = default;
  // The law's scene name (contact.law).
  virtual std::string_view name() const = 0;
  // A frictionless law carries no shear: the contact skips the return map, and its tangent stays symmetric.
  virtual bool frictional() const { return true; }
  virtual PointStateNeeds needs() const { return {}; }
  // Asked only where the point is in contact (P > 0) and the law is frictional.
  virtual SlipLimit slip_limit(const ContactPointState& point) const = 0;
  // The same law with the same coefficients (two scenes read alike compare equal).
  virtual bool same_as(const InterfaceLaw& other) const { return name() == other.name(); }
};

// Where a contact point's state comes from (the chip under it, the lubricant around it). Points are
// numbered as MortarContact::surface_positions() lists them.
class PointStateProvider {
 public:
  virtual ~PointStateProvider() = default;
  // The point's state with pressure 0 (the contact adds its own pressure).
  virtual ContactPointState state(size_t point) const = 0;
  // Why it cannot (yet) give what `needs` asks for; none when it can.
  virtual std::optional<std::string> missing(const PointStateNeeds& needs) const = 0;
};

// The provider the micro-model and the tests use: per point samples, set by the owner (after each
// accepted step in a run) and held until set again.
class SampledPointStates final : public PointStateProvider {
 public:
  SampledPointStates(size_t points, double sliding_velocity);
  ContactPointState state(size_t point) const override;
  std::optional<std::string> missing(const PointStateNeeds& needs) const override;
  // k per point, Pa (one per point, or throws Error naming the counts).
  void set_shear_strength(std::vector<double> k);
  // T per point, K.
  void set_temperature(std::vector<double> temperature);
  // Which points the lubricant reaches; an empty vector: none.
  void set_wetted(std::vector<char> wetted);
  size_t size() const { return points_; }

 private:
  void check_size(size_t given, const char* what) const;
  size_t points_;
  double sliding_velocity_;
  std::vector<double> shear_strength_, temperature_;
  std::vector<char> wetted_;
};

// How a law reads its coefficients from the scene (implemented by the scene reader, which knows the
// file, the section and the law's name for its messages). Keys are relative to the contact section;
// "wetted.x" is x in its wetted subsection. Every error names the key.
class LawKeys {
 public:
  virtual ~LawKeys() = default;
  // A coefficient the law cannot do without: missing, an error says the law needs it, with `example`.
  virtual double required_number(std::string_view key, double lo, double hi, std::string_view example) = 0;
  virtual double number(std::string_view key, double fallback, double lo, double hi) = 0;
  // A file the law cannot do without (relative to the scene's folder), checked to exist; its path.
  virtual std::string required_file(std::string_view key, std::string_view example) = 0;
  [[noreturn]] virtual void fail(std::string_view key, const std::string& message) = 0;
};

// One registered law: its scene name, a line for messages and docs, the contact keys it reads (the
// scene warns about another law's key that this one leaves unread), and its reader.
struct InterfaceLawEntry {
  std::string_view name;
  std::string_view summary;
  std::vector<std::string_view> keys;
  std::function<std::shared_ptr<const InterfaceLaw>(LawKeys&)> read;
};
// Every law, frictionless first (the default).
const std::vector<InterfaceLawEntry>& interface_laws();
// The entry of `name`; none when no law has it.
const InterfaceLawEntry* find_interface_law(std::string_view name);
// The registered names, comma-separated, for messages and --help.
std::string interface_law_names();

}  // namespace mufric::contact
