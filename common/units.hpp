#pragma once
// Physical quantities with explicit units at the human boundary (CLI, CSV headers, plots);
// SI everywhere inside: Pa, m/s, K, rad, m, s.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mufric {

enum class QuantityKind { pressure, velocity, temperature, angle, length, time, dimensionless };

// An affine map from a unit to SI: si = scale * value + offset (offset only for °C).
struct UnitToSi {
  QuantityKind kind;
  double scale;
  double offset;
};

std::string_view to_string(QuantityKind kind);
// The SI unit symbol stored in files: "Pa", "m/s", "K", "rad", "m", "s", "1".
std::string_view si_unit(QuantityKind kind);
// Example used in error messages, e.g. "800MPa".
std::string_view example_quantity(QuantityKind kind);

// Looks up a unit symbol ("MPa", "m/min", "C", "degC", "°C", "K", "deg", ...).
// Throws Error naming the unit when it is unknown, with the nearest known one (of the wanted kind
// when one is near) as a suggestion.
UnitToSi unit_to_si(std::string_view unit, std::optional<QuantityKind> wanted = std::nullopt);

// Parses "800MPa", "800 MPa", "1.2e9Pa", "100m/min", "500C". A number without a unit, an unknown
// unit, or a unit of another kind throws Error whose message starts with `field`.
double parse_quantity(std::string_view text, QuantityKind expected, std::string_view field);

// Formats an SI value in the unit people use for that kind (MPa, m/min, °C, deg).
std::string format_human(double value_si, QuantityKind kind, int precision = 4);
// A difference of two SI values (an SD, a half-width) in the same human unit, without the offset of
// °C: a temperature difference in K ("50 K").
std::string format_human_difference(double value_si, QuantityKind kind, int precision = 4);
// The human unit used by format_human, e.g. "MPa".
std::string_view human_unit(QuantityKind kind);
double si_to_human(double value_si, QuantityKind kind);

// The names of the model inputs mufric knows, spelled once: known_inputs() and every file that maps
// an input to something of its own (a wire field, a client's array, a CSV column) use these.
namespace input_name {
inline constexpr std::string_view contact_pressure = "contact_pressure";
inline constexpr std::string_view sliding_velocity = "sliding_velocity";
inline constexpr std::string_view temperature = "temperature";
inline constexpr std::string_view fibre_angle = "fibre_angle";
// The interface law's coefficients (micro/contact/interface_laws.hpp), inputs of a calibration campaign.
inline constexpr std::string_view adhesive_coefficient = "adhesive_coefficient";
inline constexpr std::string_view shear_factor = "shear_factor";
inline constexpr std::string_view childs_exponent = "childs_exponent";
}  // namespace input_name

// The model inputs mufric knows, the vocabulary of its files and its wire: in their usual order (the
// C ABI's argument order, a dataset's columns), each with its kind of quantity (so its SI unit), and
// whether the wire and the clients carry it (a meso code's contact conditions; a law coefficient
// that a calibration integrates out is not, and a model that still has one is not served:
// servable_inputs_violation). What sets an input elsewhere is its owner's: a scene key in
// micro/scene (scene::settable_inputs), a command-line flag in app/ (app/input_flags.hpp).
struct KnownInput {
  std::string_view name;
  QuantityKind kind;
  bool on_the_wire = true;
};
const std::vector<KnownInput>& known_inputs();
// The known input of that name; nullptr if mufric does not know it.
const KnownInput* find_known_input(std::string_view input_name);
// The kind of a named model input (contact_pressure → pressure, ...); dimensionless if unknown.
QuantityKind kind_of_input(std::string_view input_name);
// known_inputs()' names: contact_pressure, sliding_velocity, temperature, fibre_angle, and the law's coefficients.
const std::vector<std::string>& known_input_names();
// Whether a model with inputs of these names can be served (every input on the wire): "" if so, else
// why not, naming the first input that is not, and what to do about it.
std::string servable_inputs_violation(const std::vector<std::string>& input_names);

// Where a quantity of a kind can physically lie (SI), the one table every command checks against
// (dataset plan, scene files, training data, queries): pressure 0–100 GPa (no contact pressure
// reaches the theoretical strength of a metal, ~E/10), sliding speed 0–1000 m/s (ballistic),
// temperature from absolute zero to 10 000 K (above every melting point). Other kinds: unbounded.
struct PhysicalRange {
  double lo, hi;
};
PhysicalRange physical_range(QuantityKind kind);
// "" when `value_si` is finite and within the kind's physical range; else why not, in human units,
// e.g. "-293.8 °C is below absolute zero (-273.15 °C)".
std::string physical_range_violation(double value_si, QuantityKind kind);

}  // namespace mufric
