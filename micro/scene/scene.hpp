#pragma once
// A micro-model scene: everything one high-fidelity run needs, read from JSON. Dimensional values
// are strings with units ("800MPa", "10um", "500C", "5ns"); counts and ratios are numbers. Unknown
// keys and out-of-range values are errors that name the key (e.g. "load.pressure").
#include <array>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/units.hpp"
#include "micro/settings/option_keys.hpp"

#include "micro/contact/contact_options.hpp"
#include "micro/coupling/lubricant_settings.hpp"
#include "micro/solid/solid_options.hpp"
#include "micro/spline/profile.hpp"

namespace mufric::scene {

// Defaults below are written as a scene file's units give them (scale × value, as parse_quantity
// computes: "10um" is 10 × 1e-6, one ulp from the literal 10e-6), so that a scene file stating a
// default reads to the very same value (tested: Scene.ShippedScenesStateTheBuiltInDefaults…).
constexpr double micrometres(double x) { return 1e-6 * x; }
constexpr double nanometres(double x) { return 1e-9 * x; }
using solid::nanoseconds;

// A choice a scene file spells as a word ("lubricated", "iqn-ils") is parsed once into its enum, and
// spelled back from the same table (OptionChoice<E>::names, micro/settings/option_keys.hpp).
using mufric::choice_name;
using mufric::NamedChoice;
using mufric::OptionChoice;

// One rough surface: a measured profile (CSV), a synthetic one, or flat; fitted by a periodic spline.
struct SurfaceSpec {
  std::string csv;                 // measured profile; empty: synthetic or flat
  bool flat = false;
  spline::RoughnessSpec synthetic; // length is the scene's interval
  int degree = 3;
  int control_points = 64;
  double shift_fraction = 0.0;     // moves the profile along x by this fraction of the interval
  bool mirror = false;             // x → −x (a reflected profile, for symmetry studies)
  // Drawn from `synthetic` (a seed draws another of the same statistics), not measured or flat.
  bool is_synthetic() const { return csv.empty() && !flat; }
  bool operator==(const SurfaceSpec&) const = default;
};

// How μ is measured (README "What μ means"). Seed 000's protocol ramps the pressure while the chip
// slides and averages one draw over a fixed time window; press-slide presses first, then slides, and
// averages over a sliding distance and over tool phases / realisations, with a standard error.
enum class Protocol { press_slide, seed000 };
// What a press-slide draw draws anew: the tool alone, on the scene's one chip surface (the model of
// issue 14, kept for trend studies where shared surfaces cancel), or the tool and the chip surface
// both, from the scene's roughness statistics (μ as a property of those statistics; the default for a
// synthetic chip: with the chip fixed, every run shares its error, measured at about 15 % of μ at the
// box centre, issue 33).
enum class DrawnSurfaces { tools, tools_and_chip };

struct ProtocolSpec {
  Protocol name = Protocol::press_slide;
  // press-slide: the pressure rises over load.ramp with Γ_B held in x, then stays for press_hold
  // before Γ_B starts to slide; its velocity rises linearly to load.velocity over the first
  // kAccelerationShareOfRunIn of the run-in distance.
  double press_hold = nanoseconds(25);  // s
  // Defaults from the studies in bench/studies/press_slide_protocol/README.md ("What mu means"): the tool-to-tool scatter of μ
  // dominates the phase-to-phase one, so realisations, not phases; a run-in of 2.5 tool correlation
  // lengths and a window of 3.
  double run_in = 2e-6;           // m of sliding before the window (discarded)
  double window = micrometres(2.5);  // m of sliding over which μ is averaged
  double step_distance = nanometres(25);  // m, the longest step while sliding (dt = step_distance / |v|)
  int phases = 1;                 // tool shifts by k/phases of the interval, k = 0…phases−1
  int realisations = 4;           // synthetic tools with seeds seed, seed+1, … (same statistics)
  // With tools_and_chip, realisation r also draws the chip with seed chip_seed + r (a synthetic chip).
  DrawnSurfaces draws = DrawnSurfaces::tools_and_chip;
  int blocks = 4;                 // equal-distance blocks of the window, for the drift check
  bool operator==(const ProtocolSpec&) const = default;
};
inline constexpr double kAccelerationShareOfRunIn = 0.25;

enum class Physics { dry, lubricated };
// The scene: what one run needs, composed of each module's options (each module's own struct, with
// its defaults and reader: solid/solid_options.hpp, contact/contact_options.hpp,
// coupling/lubricant_settings.hpp) and the scene's own: the geometry, the load and the protocol.
struct Scene {
  std::string source;  // file name, for messages
  std::string base_directory = ".";  // where the file's relative paths resolve (a re-read with overrides needs it)
  Physics physics = Physics::dry;
  // geometry
  double interval = micrometres(10);   // m, the periodic width (seed 000: 1e-5 m)
  double chip_height = micrometres(5);  // m, from the mean chip surface down to Γ_B
  double initial_gap = 0.0;     // m, smallest vertical distance tool–chip at t = 0
  SurfaceSpec chip_surface, tool_surface;
  solid::ChipDiscretisation discretisation;
  solid::JohnsonCookParameters material;  // seed 000 Table 1
  // load on Γ_B
  bool pressure_controlled = true;
  double pressure = 800e6;            // Pa, pushing the chip toward the tool
  double vertical_displacement = 0.0; // m, instead of a pressure (for comparisons with other codes)
  double velocity = 100.0 / 60.0;     // m/s, horizontal, of Γ_B (chip moving in +x against a fixed tool)
  double temperature = 773.15;        // K, initial
  // The chip's equivalent plastic strain as it arrives at the tool (its hardening state; stress-free,
  // in its current shape): 0, seed 000's, a virgin chip; a chip from a cut has passed the primary
  // shear zone, ε̄ = γ/√3 with γ = cos α / (sin φ cos(φ − α)) (Merchant 1945), about 1.1 for
  // Ti6Al4V at 15° rake (data/cirp2022_ti6al4v_tin). The study that decided it: bench/studies/ti6al4v/README.md.
  double initial_plastic_strain = 0.0;
  double ramp = nanoseconds(25);      // s, the vertical load rises linearly over this time
  solid::TimeOptions time;
  // seed 000's protocol: the run's length and its averaging window (time.duration, time.average_from)
  double duration = nanoseconds(250);  // s (seed 000 Figs. 3–5)
  double average_from = 0.5 * duration;  // s, μ is averaged over [average_from, duration] (absent: its second half)
  ProtocolSpec protocol;
  // Conduction by default for press-slide, adiabatic for seed 000 (bench/studies/press_slide_protocol/README.md, the heat study).
  solid::ThermalOptions thermal;
  coupling::LubricantSettings lubricant;  // read by lubricated runs only
  contact::ContactOptions contact;
  solid::NewtonOptions newton;

  // The scene as read, with overrides applied (for the result's provenance). Kept as the user's words
  // rather than written back from the parsed values: a dataset's scene hash and `micro run --set ...`
  // replaying a sample rest on it, and parse_scene of it gives these very values (every key is read,
  // unknown keys are errors), so it cannot say more or less than the run used.
  nlohmann::json effective;
  std::vector<std::string> warnings;  // keys read but without effect (lubricant.* in a dry scene), one line each
  std::map<std::string, std::string> ineffective_keys;  // their full paths ("contact.shear_factor") → why, to ask by key
  // Every key this reading read, as it was read (type, value if absent, range): `mufric micro keys`.
  std::map<std::string, OptionKeyRead> keys_read;
  // Every value alike, the file's words (effective, source) and the warnings included.
  bool operator==(const Scene&) const = default;
};

}  // namespace mufric::scene

// The words of the scene file, in the order its error messages list them.
MUFRIC_OPTION_WORDS(scene::Physics, {"dry", scene::Physics::dry}, {"lubricated", scene::Physics::lubricated})
MUFRIC_OPTION_WORDS(scene::Protocol, {"press-slide", scene::Protocol::press_slide},
                    {"seed-000", scene::Protocol::seed000})
MUFRIC_OPTION_WORDS(scene::DrawnSurfaces, {"tools", scene::DrawnSurfaces::tools},
                    {"tools-and-chip", scene::DrawnSurfaces::tools_and_chip})

namespace mufric::scene {

// What a scene costs before it runs: unknowns, stored nonzeros and a lower bound of the memory the
// solid's stiffness, its quadrature state and its vectors take (the factor and the lubricant come
// on top), so that a scene that cannot fit is refused before it starts.
struct SceneCost {
  long long elements = 0;
  long long dofs = 0;             // solid displacement unknowns
  long long stiffness_nonzeros = 0;
  double memory_lower_bound_bytes = 0.0;
};
SceneCost estimate_scene_cost(const Scene& scene);
// The machine's physical memory, bytes.
double physical_memory_bytes();

// Reads a scene file (JSON); relative CSV paths are relative to the file. Throws Error naming the
// file and key.
nlohmann::json read_scene_json(const std::string& path);
// Applies "a.b.c=value": value parsed as JSON if it is valid JSON, else taken as a string; "a.b.c=null"
// removes the key.
void apply_override(nlohmann::json& scene, const std::string& assignment);
Scene parse_scene(const nlohmann::json& json, const std::string& source, const std::string& base_directory = ".");

// The default dry scene shipped with mufric (micro/scene/dry_default.json, compiled in).
nlohmann::json default_scene_json();

// A scene's JSON with "key=value" overrides applied, parsed.
Scene scene_with_overrides(nlohmann::json json, const std::vector<std::string>& overrides, const std::string& source,
                           const std::string& base_directory = ".");
// The model inputs a scene sets, each by its key: the load's conditions (load.pressure, ...) and the
// contact's law coefficients (contact.shear_factor, ...: contact::coefficient_inputs).
struct SettableInput {
  std::string_view input;  // common/units.hpp input_name
  std::string scene_key;
  QuantityKind kind;
};
const std::vector<SettableInput>& settable_inputs();
const SettableInput* find_settable_input(std::string_view input);

// The scene read again from its own words with SI values set at scene keys ("load.pressure" to 8e8):
// how a dataset sets a plan point's inputs, whatever scene key an input names (settable_inputs).
// Every check of the scene applies to the new values.
struct SceneValue {
  std::string_view key;  // e.g. load.pressure, contact.shear_factor
  double si;             // the value in SI
  QuantityKind kind;     // dimensionless: written as a number, else with its SI unit
};
Scene scene_with_values(const Scene& scene, const std::vector<SceneValue>& values);

// A scene file (or, for an empty path, the default scene) with "key=value" overrides applied.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides);

// A new pair's scene from a base scene: partial scenes (e.g. the work material's Johnson–Cook and
// thermal set: {"material": {...}, "thermal": {...}}) merged over it in order (RFC 7386 JSON merge
// patch), then "key=value" overrides; checked by reading it (every unit and range). `notes` say
// where each section came from and what stayed the base's default that a pair usually measures
// (the tool's surface).
struct NamedPatch {
  std::string source;  // a file's path, for the notes and errors
  nlohmann::json json;
};
struct ComposedScene {
  nlohmann::json json;
  Scene scene;
  std::vector<std::string> notes;
};
ComposedScene compose_scene(nlohmann::json base, const std::string& base_source, const std::vector<NamedPatch>& patches,
                            const std::vector<std::string>& overrides, const std::string& base_directory = ".");

}  // namespace mufric::scene
