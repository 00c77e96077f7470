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

#include "micro/contact/interface_laws.hpp"
#include "micro/contact/mortar_contact.hpp"
#include "micro/coupling/lubricated_chip.hpp"
#include "micro/fluid/navier_stokes.hpp"
#include "micro/solid/materials.hpp"
#include "micro/solid/time_integrator.hpp"
#include "micro/spline/profile.hpp"

namespace mufric::scene {

// Defaults below are written as a scene file's units give them (scale × value, as parse_quantity
// computes: "10um" is 10 × 1e-6, one ulp from the literal 10e-6), so that a scene file stating a
// default reads to the very same value (tested: Scene.ShippedScenesStateTheBuiltInDefaults…).
constexpr double micrometres(double x) { return 1e-6 * x; }
constexpr double nanometres(double x) { return 1e-9 * x; }
constexpr double nanoseconds(double x) { return 1e-9 * x; }

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
  // Defaults from the studies in bench/RESULTS.md ("What mu means"): the tool-to-tool scatter of μ
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
// Heat: adiabatic (seed 000: each point keeps the heat of its plastic work) or conducted through the
// chip (Γ_B held at load.temperature, the contact face insulated).
enum class ThermalModel { adiabatic, conduction };
enum class Compressibility { none, linear, dowson_higginson };
enum class FilmFill { gap, after_pressing };
enum class CavitationModel { none, mass_conserving };
enum class LeakModel { none, ambient, cell_mean };

// The lubricant in the pockets (physics "lubricated"; ignored by a dry run, so one scene serves both).
struct LubricantSpec {
  double density = 800.0;      // kg/m³ (seed 000 Table 2)
  double viscosity = 0.032;    // Pa s (seed 000 Table 2)
  // "none" (incompressible, seed 000), "linear" (ρ/ρ₀ = 1 + p/K₀) or "dowson-higginson" (ρ/ρ₀ =
  // 1 + (p/K₀)/(1 + 1.7 GPa⁻¹ p)); K₀ the bulk modulus at p = 0, Dowson & Higginson's 1/(0.6 GPa⁻¹) by
  // default (fluid::FluidProperties).
  Compressibility compressibility = Compressibility::none;
  double bulk_modulus = fluid::kDowsonHigginsonBulkModulus;  // Pa
  int elements_x = 0;          // film columns; 0: the chip's discretisation.elements_x
  int elements_y = 4;          // elements across the film
  // m, the film where the chip touches the tool. 20 nm: thinner ones (5, 10 nm) stop the coarse
  // scene's coupling, 20 and 40 nm give μ within 4 % of each other (bench/RESULTS.md).
  double min_film = 20e-9;
  // What the film holds: "gap", all the lubricant in the initial gap from t = 0 (seed-000 protocol's
  // default: it carries the load and no contact forms); "after-pressing" (press-slide's default), the
  // chip pressed dry (the lubricant drained) and the film formed in the gap it leaves when sliding starts.
  FilmFill fill = FilmFill::after_pressing;
  // Tension in the film: "none", the liquid holds any (seed 000's model); "mass-conserving", where the
  // liquid would pull the chip below cavitation_pressure a cavity opens (micro/coupling/cavitation.hpp).
  CavitationModel cavitation = CavitationModel::mass_conserving;
  double cavitation_pressure = 0.0;  // Pa, relative to the ambient zero of the applied load
  // Liquid flowing out of the plane of the cell (coupling::LubricantOptions::leak): "none", sealed in
  // it (seed 000's protocol's default); "ambient" (press-slide's default), draining toward the ambient
  // zero; "cell-mean", moving between the film's parts toward its mean pressure (the film keeps its
  // liquid). Over leak_length either side of the slice. Decided from a study (README, "The lubricant";
  // bench/RESULTS.md, "The lubricant, eighth pass").
  LeakModel leak = LeakModel::ambient;
  double leak_length = 1e-6;  // m: about the roughness' correlation length (tool 0.8 µm, chip 1 µm)
  // Minimum films over which the fluid's load fades out into a contact spot (a continuous switch).
  double contact_fade = 2.0;
  // α_R, Pa s/m; 0: the automatic ρ_chip h_chip / max(Δt, time.step) + robin_stiffness Δt.
  double robin_weight = 0.0;
  double robin_stiffness = 0.0;  // β, Pa/m: the chip's stiffness in the automatic α_R (coupling/lubricated_chip.hpp)
  // How the film's interior follows its walls: "columns" (algebraic, cannot fold) or "elastic" (EMUM,
  // with mesh_stiffening the χ of its Jacobian-based stiffening); micro/coupling/lubricated_chip.hpp.
  coupling::FilmMeshMotion mesh_motion = coupling::FilmMeshMotion::columns;
  double mesh_stiffening = 1.0;
  coupling::Acceleration acceleration = coupling::Acceleration::iqn_ils;  // iqn-ils, aitken or relaxation
  double relaxation = 0.5;
  int reuse_steps = 8;
  double qr_filter = 1e-8;
  // Relative, of the interface load and displacement. The chip's own Newton tolerance, amplified by α_R/Δt,
  // leaves the load a noise floor near 1e-4 of its size once the chip yields; with contact spots
  // opening and closing beside the film the iteration stalls near 1e-3 at some points of the box, and
  // 3e-3 moves μ by 0.4 % where both converge (bench/RESULTS.md).
  double coupling_tolerance = 3e-3;
  // Of load.pressure: the interface traction's change, as a root mean square over the film's wall
  // samples, below this is converged whatever the film's own traction (CouplingOptions::load_tolerance).
  // Its force on the chip then errs by at most this share of the applied load. 0: the relative
  // coupling_tolerance alone. Ignored with a displacement-controlled load (no pressure to scale by).
  double traction_tolerance = 3e-4;
  // The liquid a step's mismatch of interface velocities (fluid against film wall, (λ − λ̃)/α_R)
  // moves through the wall, over the film's volume. The traction tolerance alone left it at up to
  // 2 % per step and μ 8 % off; 1e-3 puts μ within 0.6 % of 1e-5 (bench/RESULTS.md).
  double volume_tolerance = 1e-3;
  int max_coupling_iterations = 50;
  // Exchanges without a new best traction change after which a step fails and is cut back (0: never).
  int stall_iterations = 0;
  // Restarts of a step's interface iteration after a solver failed on an accelerated iterate,
  // before the step fails and is cut back (CouplingOptions::max_restarts).
  int coupling_restarts = 0;
  bool operator==(const LubricantSpec&) const = default;
};

struct Scene {
  std::string source;  // file name, for messages
  std::string base_directory = ".";  // where the file's relative paths resolve (a re-read with overrides needs it)
  Physics physics = Physics::dry;
  // geometry
  double interval = micrometres(10);   // m, the periodic width (seed 000: 1e-5 m)
  double chip_height = micrometres(5);  // m, from the mean chip surface down to Γ_B
  double initial_gap = 0.0;     // m, smallest vertical distance tool–chip at t = 0
  SurfaceSpec chip_surface, tool_surface;
  // discretisation
  int degree = 2;
  int elements_x = 64;
  int elements_y = 12;
  double grading = 2.0;          // spans across the height shrink toward the surface: v_k = 1 − (1 − k/n)^grading
  // full: the displacement formulation (seed 000's); mean-dilatation: F-bar (solid_problem.hpp)
  solid::VolumetricTreatment volumetric = solid::VolumetricTreatment::full;
  int contact_points_per_span = 0;  // 0: degree + 3
  // material (seed 000 Table 1)
  solid::JohnsonCookParameters material;
  // load on Γ_B
  bool pressure_controlled = true;
  double pressure = 800e6;            // Pa, pushing the chip toward the tool
  double vertical_displacement = 0.0; // m, instead of a pressure (for comparisons with other codes)
  double velocity = 100.0 / 60.0;     // m/s, horizontal, of Γ_B (chip moving in +x against a fixed tool)
  double temperature = 773.15;        // K, initial
  double ramp = nanoseconds(25);      // s, the vertical load rises linearly over this time
  // time
  solid::TimeScheme scheme = solid::TimeScheme::generalized_alpha;
  // ρ∞ 0.5: damps the chip's thickness vibration that the pressure ramp excites, which with 0.8 still
  // rang through the averaging window, and gave μ closest to the small-step runs (bench/RESULTS.md).
  double spectral_radius = 0.5;
  double dt = 1e-9;                   // s, the first step
  double max_dt = dt;                 // s, the longest step the step-size control may take (absent: time.step)
  double duration = nanoseconds(250);  // s (seed 000 Figs. 3–5)
  double average_from = 0.5 * duration;  // s, μ is averaged over [average_from, duration] (absent: its second half)
  ProtocolSpec protocol;
  // The default follows the protocol: conduction for press-slide, adiabatic for seed 000
  // (bench/RESULTS.md, the heat study).
  ThermalModel thermal_model = ThermalModel::conduction;
  bool heat_conduction() const { return thermal_model == ThermalModel::conduction; }
  double conductivity = 50.0;  // W/(m K), plain carbon steel near room temperature (AISI 1045: ~50)
  LubricantSpec lubricant;
  // contact
  double penalty = 2e18;              // Pa/m
  // The interface law (frictionless unless contact.law says otherwise), stick's penalty, the heat partition.
  contact::ContactInterface contact_interface{.law = std::make_shared<contact::FrictionlessLaw>()};
  // solver
  double relative_tolerance = 1e-9;
  int max_newton_iterations = 30;
  int max_cutbacks = 8;
  numerics::LinearSolverKind linear_solver = numerics::LinearSolverKind::cholesky;  // falls back to LU per matrix

  // The scene as read, with overrides applied (for the result's provenance). Kept as the user's words
  // rather than written back from the parsed values: a dataset's scene hash and `micro run --set ...`
  // replaying a sample rest on it, and parse_scene of it gives these very values (every key is read,
  // unknown keys are errors), so it cannot say more or less than the run used.
  nlohmann::json effective;
  std::vector<std::string> warnings;  // keys read but without effect (lubricant.* in a dry scene), one line each
  std::map<std::string, std::string> ineffective_keys;  // their full paths ("contact.shear_factor") → why, to ask by key
  // Every value alike, the file's words (effective, source) and the warnings included.
  bool operator==(const Scene&) const = default;
};

}  // namespace mufric::scene

namespace mufric {
// The words of the scene file, in the order its error messages list them.
template <>
struct OptionChoice<scene::Physics> {
  static constexpr std::array<NamedChoice<scene::Physics>, 2> names{{{"dry", scene::Physics::dry}, {"lubricated", scene::Physics::lubricated}}};
};
template <>
struct OptionChoice<scene::ThermalModel> {
  static constexpr std::array<NamedChoice<scene::ThermalModel>, 2> names{
      {{"adiabatic", scene::ThermalModel::adiabatic}, {"conduction", scene::ThermalModel::conduction}}};
};
template <>
struct OptionChoice<scene::Protocol> {
  static constexpr std::array<NamedChoice<scene::Protocol>, 2> names{
      {{"press-slide", scene::Protocol::press_slide}, {"seed-000", scene::Protocol::seed000}}};
};
template <>
struct OptionChoice<scene::DrawnSurfaces> {
  static constexpr std::array<NamedChoice<scene::DrawnSurfaces>, 2> names{
      {{"tools", scene::DrawnSurfaces::tools}, {"tools-and-chip", scene::DrawnSurfaces::tools_and_chip}}};
};
template <>
struct OptionChoice<solid::TimeScheme> {
  static constexpr std::array<NamedChoice<solid::TimeScheme>, 2> names{
      {{"generalized-alpha", solid::TimeScheme::generalized_alpha}, {"quasi-static", solid::TimeScheme::quasi_static}}};
};
template <>
struct OptionChoice<solid::VolumetricTreatment> {
  static constexpr std::array<NamedChoice<solid::VolumetricTreatment>, 2> names{
      {{"full", solid::VolumetricTreatment::full}, {"mean-dilatation", solid::VolumetricTreatment::mean_dilatation}}};
};
template <>
struct OptionChoice<numerics::LinearSolverKind> {
  static constexpr std::array<NamedChoice<numerics::LinearSolverKind>, 2> names{
      {{"lu", numerics::LinearSolverKind::lu}, {"cholesky", numerics::LinearSolverKind::cholesky}}};
};
template <>
struct OptionChoice<scene::Compressibility> {
  static constexpr std::array<NamedChoice<scene::Compressibility>, 3> names{{{"none", scene::Compressibility::none},
                                                                      {"linear", scene::Compressibility::linear},
                                                                      {"dowson-higginson", scene::Compressibility::dowson_higginson}}};
};
template <>
struct OptionChoice<scene::FilmFill> {
  static constexpr std::array<NamedChoice<scene::FilmFill>, 2> names{
      {{"gap", scene::FilmFill::gap}, {"after-pressing", scene::FilmFill::after_pressing}}};
};
template <>
struct OptionChoice<scene::CavitationModel> {
  static constexpr std::array<NamedChoice<scene::CavitationModel>, 2> names{
      {{"none", scene::CavitationModel::none}, {"mass-conserving", scene::CavitationModel::mass_conserving}}};
};
template <>
struct OptionChoice<scene::LeakModel> {
  static constexpr std::array<NamedChoice<scene::LeakModel>, 3> names{
      {{"none", scene::LeakModel::none}, {"ambient", scene::LeakModel::ambient}, {"cell-mean", scene::LeakModel::cell_mean}}};
};
template <>
struct OptionChoice<coupling::FilmMeshMotion> {
  static constexpr std::array<NamedChoice<coupling::FilmMeshMotion>, 2> names{
      {{"columns", coupling::FilmMeshMotion::columns}, {"elastic", coupling::FilmMeshMotion::elastic}}};
};
template <>
struct OptionChoice<coupling::Acceleration> {
  static constexpr std::array<NamedChoice<coupling::Acceleration>, 3> names{
      {{"iqn-ils", coupling::Acceleration::iqn_ils},
       {"aitken", coupling::Acceleration::aitken},
       {"relaxation", coupling::Acceleration::constant_relaxation}}};
};

}  // namespace mufric

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
// The scene read again from its own words with SI values set at scene keys ("load.pressure" to 8e8):
// how a dataset sets a plan point's inputs, whatever scene key an input names (common/units.hpp's
// KnownInput::scene_key). Every check of the scene applies to the new values.
struct SceneValue {
  std::string_view key;  // e.g. load.pressure, contact.shear_factor
  double si;             // the value in SI
  QuantityKind kind;     // dimensionless: written as a number, else with its SI unit
};
Scene scene_with_values(const Scene& scene, const std::vector<SceneValue>& values);

// A scene file (or, for an empty path, the default scene) with "key=value" overrides applied.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides);

}  // namespace mufric::scene
