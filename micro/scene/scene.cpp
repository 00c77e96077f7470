#include "micro/scene/scene.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
#include "micro/contact/interface_laws.hpp"
#include "micro/settings/option_keys.hpp"

namespace mufric::scene {
namespace {

using nlohmann::json;

using Section = OptionKeys;

constexpr double kHuge = 1e300;

SurfaceSpec read_surface(Section s, const std::string& base_directory) {
  SurfaceSpec out;
  const int kinds = s.has("csv") + s.has("synthetic") + s.has("flat");
  if (kinds != 1) s.fail("", "give exactly one of csv, synthetic or flat");
  if (s.has("csv")) {
    out.csv = s.text("csv", "", {});
    if (std::filesystem::path(out.csv).is_relative()) out.csv = (std::filesystem::path(base_directory) / out.csv).string();
    if (!std::filesystem::exists(out.csv)) s.fail("csv", "no such file '" + out.csv + "'");
  }
  out.flat = s.boolean("flat", false);
  if (s.has("flat") && !out.flat) s.fail("flat", "only `\"flat\": true` is meaningful");
  if (s.has("synthetic")) {
    Section g = s.child("synthetic");
    out.synthetic.ra = g.quantity("ra", QuantityKind::length, out.synthetic.ra, 1e-12, 1e-3);
    out.synthetic.correlation_length =
        g.quantity("correlation_length", QuantityKind::length, out.synthetic.correlation_length, 1e-12, 1e-2);
    out.synthetic.samples = g.integer("samples", out.synthetic.samples, 16, 1 << 20);
    out.synthetic.seed = static_cast<std::uint64_t>(g.integer("seed", static_cast<int>(out.synthetic.seed), 0, 2147483647));
    g.finish();
  }
  Section fit = s.child("fit");
  out.degree = fit.integer("degree", out.degree, 1, spline::kMaxDegree);
  out.control_points = fit.integer("control_points", out.control_points, 4, 100000);
  fit.finish();
  out.shift_fraction = s.number("shift", out.shift_fraction, -1.0, 1.0);
  out.mirror = s.boolean("mirror", out.mirror);
  s.finish();
  return out;
}

// Where a law's key lives: "x" in the contact section, "wetted.x" as x in its wetted subsection.
std::pair<Section&, std::string> law_key_section(std::string_view key, Section& contact, Section& wetted) {
  constexpr std::string_view kWettedPrefix = "wetted.";
  if (key.starts_with(kWettedPrefix)) return {wetted, std::string(key.substr(kWettedPrefix.size()))};
  return {contact, std::string(key)};
}

// The law's coefficient keys as the scene file spells them (contact.*, contact.wetted.*): reads for
// contact::LawKeys, with the file, the key and the law named in every error. A law reads only the
// keys its registry entry declares (a logic error otherwise: the scene's warnings about another
// law's keys rest on those lists).
class SceneLawKeys final : public contact::LawKeys {
 public:
  SceneLawKeys(Section& contact, Section& wetted, const contact::InterfaceLawEntry& law, const std::string& base_directory)
      : contact_(contact), wetted_(wetted), law_(law), base_directory_(base_directory) {}
  double required_number(std::string_view key, double lo, double hi, std::string_view example) override {
    auto [section, name] = locate(key);
    require(section, name, example);
    return section.number(name, 0.0, lo, hi);
  }
  double number(std::string_view key, double fallback, double lo, double hi) override {
    auto [section, name] = locate(key);
    return section.number(name, fallback, lo, hi);
  }
  std::string required_file(std::string_view key, std::string_view example) override {
    auto [section, name] = locate(key);
    require(section, name, example);
    std::string path = section.text(name, "", {});
    if (std::filesystem::path(path).is_relative()) path = (std::filesystem::path(base_directory_) / path).string();
    if (!std::filesystem::exists(path)) section.fail(name, "no such file '" + path + "'");
    return path;
  }
  [[noreturn]] void fail(std::string_view key, const std::string& message) override {
    auto [section, name] = locate(key);
    section.fail(name, message);
  }

 private:
  std::pair<Section&, std::string> locate(std::string_view key) {
    if (std::find(law_.keys.begin(), law_.keys.end(), key) == law_.keys.end()) {
      throw std::logic_error("contact law " + std::string(law_.name) + " reads contact." + std::string(key) +
                             ", which its registry entry does not declare");
    }
    return law_key_section(key, contact_, wetted_);
  }
  void require(const Section& section, const std::string& name, std::string_view example) const {
    if (!section.has(name)) {
      section.fail(name, "required when contact.law is " + std::string(law_.name) + " (" + std::string(example) + ")");
    }
  }
  Section& contact_;
  Section& wetted_;
  const contact::InterfaceLawEntry& law_;
  const std::string& base_directory_;
};

// Another law's key that this one leaves unread is a warning, not an error: switching laws with
// --set keeps a scene's other coefficients.
void warn_about_other_laws_keys(Section& contact, Section& wetted, const contact::InterfaceLawEntry& law) {
  for (const auto& other : contact::interface_laws()) {
    for (const std::string_view key : other.keys) {
      if (std::find(law.keys.begin(), law.keys.end(), key) != law.keys.end()) continue;
      auto [section, name] = law_key_section(key, contact, wetted);
      section.ineffective(name, "contact.law is " + std::string(law.name));
    }
  }
}

// contact: the penalty, the interface law (read by its registry entry) and what the contact does
// around any law (stick's tangential penalty, the heat partition).
void read_contact(Section c, Scene& s, const std::string& base_directory) {
  s.penalty = c.number("penalty", s.penalty, 1e3, 1e30);
  // The interfacial law: frictionless is seed 000's model (μ from ploughing alone) and the default.
  std::vector<std::string> names;
  for (const auto& law : contact::interface_laws()) names.emplace_back(law.name);
  const std::string law_name = c.text("law", names.front(), names);
  const contact::InterfaceLawEntry& entry = *contact::find_interface_law(law_name);
  const bool has_wetted = c.has("wetted");
  Section wetted = c.child("wetted");
  SceneLawKeys keys(c, wetted, entry, base_directory);
  contact::ContactInterface& interface = s.contact_interface;
  interface.law = entry.read(keys);
  warn_about_other_laws_keys(c, wetted, entry);
  wetted.finish();
  const bool frictional = interface.law->frictional();
  // Stick's regularisation; absent, 0: the contact's default, a tenth of the normal penalty
  // (contact::kTangentialPenaltyRatio, applied in one place, MortarContact). The heat partition: the
  // share of the frictional heat that enters the chip (contact::kDefaultHeatPartition says why 0.5).
  if (frictional) {
    interface.tangential_penalty = c.number("tangential_penalty", 0.0, 1e3, 1e30);
    interface.heat_partition = c.number("heat_partition", contact::kDefaultHeatPartition, contact::kHeatPartitionRange.lo,
                                        contact::kHeatPartitionRange.hi);
  } else {
    for (const char* key : {"tangential_penalty", "heat_partition"}) c.ineffective(key, "contact.law is " + law_name);
  }
  // Wetted spots take the law's wetted coefficients (contact::kDefaultWetted* say where the defaults
  // come from); only a lubricated scene has a film to wet them.
  if (has_wetted && frictional && s.physics != Physics::lubricated) {
    c.report().warn("contact.wetted is read but has no effect: the scene's physics is dry (no film wets a spot)");
  }
  if (frictional && !s.heat_conduction()) {
    c.report().warn("the frictional heat of contact.law " + law_name +
                    " is not passed to the chip: thermal.model is adiabatic (only conduction takes heat in through the surface)");
  }
  c.finish();
}

}  // namespace

nlohmann::json read_scene_json(const std::string& path) {
  const auto text = read_whole_file(path);
  if (!text) throw Error(path + ": cannot read the scene file");
  try {
    return json::parse(*text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for a number like 1e999
    throw Error(path + ": not valid JSON: " + e.what());
  }
}

void apply_override(nlohmann::json& scene, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) throw Error("--set '" + assignment + "': expected key.path=value");
  const std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  json value;
  try {
    value = json::parse(text);
  } catch (const json::exception&) {
    value = text;  // "800MPa" and other unit strings (and numbers JSON cannot hold, refused by the key's check)
  }
  json* node = &scene;
  size_t start = 0;
  while (true) {
    const size_t dot = path.find('.', start);
    const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (key.empty()) throw Error("--set '" + assignment + "': empty key in '" + path + "'");
    if (dot == std::string::npos) {
      if (value.is_null()) {
        node->erase(key);  // "key=null" removes the key (e.g. load.pressure, to give vertical_displacement)
      } else {
        (*node)[key] = value;
      }
      return;
    }
    if (!node->contains(key)) (*node)[key] = json::object();
    node = &(*node)[key];
    if (!node->is_object()) throw Error("--set '" + assignment + "': '" + key + "' is not an object");
    start = dot + 1;
  }
}

namespace {

// geometry: the periodic interval, the chip height, the initial gap and the two surfaces.
void read_geometry(Section g, Scene& s, const std::string& base_directory) {
  s.interval = g.quantity("interval", QuantityKind::length, s.interval, 1e-9, 1e-2);
  s.chip_height = g.quantity("chip_height", QuantityKind::length, s.chip_height, 1e-9, 1e-2);
  s.initial_gap = g.quantity("initial_gap", QuantityKind::length, s.initial_gap, 0.0, 1e-3);
  if (!g.has("chip_surface")) g.fail("chip_surface", "missing");
  if (!g.has("tool_surface")) g.fail("tool_surface", "missing");
  s.chip_surface = read_surface(g.child("chip_surface"), base_directory);
  s.tool_surface = read_surface(g.child("tool_surface"), base_directory);
  g.finish();
}

// discretisation: the chip's IGA patch.
void read_discretisation(Section d, Scene& s) {
  s.degree = d.integer("degree", s.degree, 1, 6);
  s.elements_x = d.integer("elements_x", s.elements_x, 4, 100000);
  s.elements_y = d.integer("elements_y", s.elements_y, 1, 100000);
  s.grading = d.number("grading", s.grading, 1.0, 6.0);
  s.volumetric = d.choice("volumetric", s.volumetric);
  s.contact_points_per_span = d.integer("contact_points_per_span", s.contact_points_per_span, 0, 20);
  d.finish();
}

// material: Johnson–Cook and the thermal constants (seed 000 Table 1).
void read_material(Section m, Scene& s) {
  auto& p = s.material;
  p.youngs_modulus = m.quantity("youngs_modulus", QuantityKind::pressure, p.youngs_modulus, 1e6, 1e13);
  p.poisson_ratio = m.number("poisson_ratio", p.poisson_ratio, -0.99, 0.499);
  p.density = m.number("density", p.density, 1.0, 1e5);
  p.a = m.quantity("a", QuantityKind::pressure, p.a, 1.0, 1e11);
  p.b = m.quantity("b", QuantityKind::pressure, p.b, 0.0, 1e11);
  p.c = m.number("c", p.c, 0.0, 10.0);
  p.n = m.number("n", p.n, 0.0, 5.0);
  p.m = m.number("m", p.m, 0.01, 10.0);
  p.reference_strain_rate = m.number("reference_strain_rate", p.reference_strain_rate, 1e-12, 1e12);
  p.transition_temperature = m.quantity("transition_temperature", QuantityKind::temperature, p.transition_temperature, 0.0, 1e4);
  p.melting_temperature = m.quantity("melting_temperature", QuantityKind::temperature, p.melting_temperature, 1.0, 1e4);
  if (!(p.melting_temperature > p.transition_temperature)) m.fail("melting_temperature", "must exceed transition_temperature");
  p.specific_heat = m.number("specific_heat", p.specific_heat, 1.0, 1e5);
  p.heat_fraction = m.number("heat_fraction", p.heat_fraction, 0.0, 1.0);
  m.finish();
}

// load: what drives Γ_B: a pressure or a vertical displacement, the sliding velocity, the temperature, the ramp.
void read_load(Section l, Scene& s) {
  if (l.has("pressure") == l.has("vertical_displacement")) {
    l.fail("", "give exactly one of pressure or vertical_displacement");
  }
  s.pressure_controlled = l.has("pressure");
  // Physical ranges from the one table every command checks (common/units.hpp).
  const PhysicalRange pressures = physical_range(QuantityKind::pressure);
  const PhysicalRange speeds = physical_range(QuantityKind::velocity);
  const PhysicalRange temperatures = physical_range(QuantityKind::temperature);
  s.pressure = l.quantity("pressure", QuantityKind::pressure, s.pressure, pressures.lo, pressures.hi);
  s.vertical_displacement = l.quantity("vertical_displacement", QuantityKind::length, s.vertical_displacement, -1e-3, 1e-3);
  s.velocity = l.quantity("velocity", QuantityKind::velocity, s.velocity, -speeds.hi, speeds.hi);  // signed: direction
  s.temperature = l.quantity("temperature", QuantityKind::temperature, s.temperature, temperatures.lo, temperatures.hi);
  s.ramp = l.quantity("ramp", QuantityKind::time, s.ramp, 0.0, 1.0);
  l.finish();
}

// time: the time integration and seed 000's averaging window.
void read_time(Section t, Scene& s) {
  s.scheme = t.choice("scheme", s.scheme);
  s.spectral_radius = t.number("spectral_radius", s.spectral_radius, 0.0, 1.0);
  s.dt = t.quantity("step", QuantityKind::time, s.dt, 1e-15, 1.0);
  s.duration = t.quantity("duration", QuantityKind::time, s.duration, 1e-15, 10.0);
  if (s.dt > s.duration) t.fail("step", "is longer than the duration");
  s.max_dt = t.quantity("max_step", QuantityKind::time, s.dt, 1e-15, 1.0);
  if (s.max_dt < s.dt) t.fail("max_step", "is shorter than time.step");
  s.average_from = t.quantity("average_from", QuantityKind::time, 0.5 * s.duration, 0.0, kHuge);
  if (s.average_from >= s.duration) t.fail("average_from", "must lie before the end of the run");
  t.finish();
}

// protocol: what μ means (README "What μ means"): press-slide or seed 000's, and the draws.
void read_protocol(Section p, Scene& s) {
  auto& q = s.protocol;
  q.name = p.choice("name", q.name);
  q.press_hold = p.quantity("press_hold", QuantityKind::time, q.press_hold, 0.0, 1.0);
  q.run_in = p.quantity("run_in", QuantityKind::length, q.run_in, 0.0, 1.0);
  q.window = p.quantity("window", QuantityKind::length, q.window, 1e-12, 1.0);
  q.step_distance = p.quantity("step_distance", QuantityKind::length, q.step_distance, 1e-12, 1.0);
  q.phases = p.integer("phases", q.phases, 1, 1024);
  q.realisations = p.integer("realisations", q.realisations, 1, 1024);
  q.blocks = p.integer("blocks", q.blocks, 1, 100);
  if (q.name == Protocol::press_slide) {
    if (s.velocity == 0.0) p.fail("name", "press-slide averages over a sliding distance: load.velocity must not be zero");
    if (s.scheme != solid::TimeScheme::generalized_alpha && s.pressure_controlled) {
      p.fail("name", "press-slide under a pressure presses dynamically (the chip's inertia holds it until the contact "
                     "closes): time.scheme must be generalized-alpha, or load the chip by vertical_displacement");
    }
    if (q.realisations > 1 && !s.tool_surface.is_synthetic()) {
      p.fail("realisations", "realisations redraw a synthetic tool with other seeds; this tool is " +
                                 std::string(s.tool_surface.flat ? "flat" : "a measured profile") +
                                 " (use phases to average over its positions)");
    }
    if (q.step_distance > q.window) p.fail("step_distance", "is longer than the window");
    const bool chip_drawable = s.chip_surface.is_synthetic();
    q.draws = p.choice("draws", chip_drawable ? DrawnSurfaces::tools_and_chip : DrawnSurfaces::tools);
    if (q.draws == DrawnSurfaces::tools_and_chip && !chip_drawable) {
      p.fail("draws", "tools-and-chip draws the chip surface anew; this chip is " +
                          std::string(s.chip_surface.flat ? "flat" : "a measured profile") + " (use tools)");
    }
  }
  if (q.name == Protocol::seed000) q.draws = DrawnSurfaces::tools;  // one draw, the scene's own surfaces
  p.finish();
}

// thermal: adiabatic or conducted heat.
void read_thermal(Section h, Scene& s) {
  const ThermalModel fallback = s.protocol.name == Protocol::seed000 ? ThermalModel::adiabatic : ThermalModel::conduction;
  s.thermal_model = h.choice("model", fallback);
  s.conductivity = h.number("conductivity", s.conductivity, 0.0, 1e4);
  h.finish();
}

// lubricant: the lubricant in the pockets (read by lubricated runs only).
void read_lubricant(Section f, Scene& s) {
  auto& l = s.lubricant;
  l.density = f.number("density", l.density, 1.0, 1e5);
  l.viscosity = f.number("viscosity", l.viscosity, 1e-6, 1e6);
  l.compressibility = f.choice("compressibility", l.compressibility);
  l.bulk_modulus = f.quantity("bulk_modulus", QuantityKind::pressure, l.bulk_modulus, 1e6, 1e13);
  l.elements_x = f.integer("elements_x", l.elements_x, 0, 100000);
  l.elements_y = f.integer("elements_y", l.elements_y, 1, 1000);
  l.min_film = f.quantity("min_film", QuantityKind::length, l.min_film, 1e-12, 1e-6);
  l.fill = f.choice("fill", s.protocol.name == Protocol::press_slide ? l.fill : FilmFill::gap);
  if (l.fill == FilmFill::after_pressing && s.protocol.name != Protocol::press_slide) {
    f.fail("fill", "after-pressing needs the press-slide protocol (seed 000's presses while sliding)");
  }
  l.cavitation = f.choice("cavitation", l.cavitation);
  l.cavitation_pressure = f.quantity("cavitation_pressure", QuantityKind::pressure, l.cavitation_pressure, -1e9, 1e9);
  l.leak = f.choice("leak", s.protocol.name == Protocol::press_slide ? l.leak : LeakModel::none);
  l.leak_length = f.quantity("leak_length", QuantityKind::length, l.leak_length, 1e-9, 1.0);
  l.contact_fade = f.number("contact_fade", l.contact_fade, 1.01, 100.0);
  l.robin_weight = f.number("robin_weight", l.robin_weight, 0.0, 1e30);
  l.robin_stiffness = f.number("robin_stiffness", l.robin_stiffness, 0.0, 1e25);
  l.mesh_motion = f.choice("mesh_motion", l.mesh_motion);
  l.mesh_stiffening = f.number("mesh_stiffening", l.mesh_stiffening, 0.0, 5.0);
  l.acceleration = f.choice("acceleration", l.acceleration);
  l.relaxation = f.number("relaxation", l.relaxation, 1e-6, 1.0);
  l.reuse_steps = f.integer("reuse_steps", l.reuse_steps, 0, 100);
  l.qr_filter = f.number("qr_filter", l.qr_filter, 0.0, 0.999);
  l.coupling_tolerance = f.number("coupling_tolerance", l.coupling_tolerance, 1e-14, 1e-1);
  l.traction_tolerance = f.number("traction_tolerance", l.traction_tolerance, 0.0, 1e-1);
  l.volume_tolerance = f.number("volume_tolerance", l.volume_tolerance, 1e-14, 1.0);
  l.max_coupling_iterations = f.integer("max_coupling_iterations", l.max_coupling_iterations, 1, 10000);
  l.stall_iterations = f.integer("stall_iterations", l.stall_iterations, 0, 10000);
  l.coupling_restarts = f.integer("coupling_restarts", l.coupling_restarts, 0, 100);
  f.finish();
}

// solver: Newton's tolerances and the linear solver.
void read_solver(Section v, Scene& s) {
  s.relative_tolerance = v.number("relative_tolerance", s.relative_tolerance, 1e-15, 1e-2);
  s.max_newton_iterations = v.integer("max_newton_iterations", s.max_newton_iterations, 1, 1000);
  s.max_cutbacks = v.integer("max_cutbacks", s.max_cutbacks, 0, 40);
  // Cholesky by default: frictionless penalty contact, associative plasticity with the temperature
  // frozen over a step and the mass term make the tangent symmetric positive definite (measured:
  // symmetric to 1e-16); CHOLMOD halves the solve time against UMFPACK at 1800–3300 dofs
  // (bench/RESULTS.md) and hands any tangent it finds indefinite to LU.
  s.linear_solver = v.choice("linear_solver", s.linear_solver);
  v.finish();
}

// A scene whose stiffness and quadrature state alone exceed the machine's memory, refused before it
// starts with the estimate (`mufric micro check` prints it).
void refuse_a_scene_that_cannot_fit(const Scene& s) {
  const SceneCost cost = estimate_scene_cost(s);
  if (cost.memory_lower_bound_bytes > physical_memory_bytes()) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "%d x %d elements of degree %d (%lld unknowns) need at least %.3g GB for the stiffness and the "
                  "quadrature state alone, more than this machine's %.3g GB (`mufric micro check` prints the estimate)",
                  s.elements_x, s.elements_y, s.degree, cost.dofs, cost.memory_lower_bound_bytes / 1e9,
                  physical_memory_bytes() / 1e9);
    throw Error(s.source + ": discretisation: " + text);
  }
}

}  // namespace

Scene parse_scene(const nlohmann::json& j, const std::string& source, const std::string& base_directory) {
  Scene s;
  s.source = source;
  s.base_directory = base_directory;
  s.effective = j;
  OptionReport report;
  Section root(j, "", source, report);
  s.physics = root.choice("physics", s.physics);
  read_geometry(root.child("geometry"), s, base_directory);
  read_discretisation(root.child("discretisation"), s);
  read_material(root.child("material"), s);
  read_load(root.child("load"), s);
  read_time(root.child("time"), s);
  read_protocol(root.child("protocol"), s);
  read_thermal(root.child("thermal"), s);
  read_lubricant(root.child("lubricant"), s);
  read_contact(root.child("contact"), s, base_directory);
  read_solver(root.child("solver"), s);
  root.finish();
  if (s.physics == Physics::dry && j.contains("lubricant")) {
    // Every lubricant key given is without effect (a dataset varying one would vary nothing).
    for (const auto& [key, value] : j.at("lubricant").items()) {
      report.ineffective_keys.emplace("lubricant." + key, "the scene's physics is dry");
    }
    report.warn("lubricant.* is read but has no effect: the scene's physics is dry (physics=lubricated to use it)");
  }
  s.warnings = report.warnings;
  s.ineffective_keys = report.ineffective_keys;
  refuse_a_scene_that_cannot_fit(s);
  return s;
}

SceneCost estimate_scene_cost(const Scene& scene) {
  // A periodic B-spline of degree p on n spans has n functions along x and n + p across; each
  // function overlaps (2p + 1)² others in 2D, for each of 2 displacement components.
  constexpr double kBytesPerNonzero = 8.0 + 4.0;         // value and column index (CSC/CSR)
  constexpr double kStateDoublesPerQuadraturePoint = 24; // plastic strain, back state, temperature, history
  constexpr double kVectorsPerDof = 12;                  // displacement, velocity, acceleration, residual, ...
  SceneCost c;
  const auto p = static_cast<long long>(scene.degree);
  c.elements = static_cast<long long>(scene.elements_x) * scene.elements_y;
  c.dofs = 2LL * scene.elements_x * (scene.elements_y + p);
  const long long overlap = (2 * p + 1) * (2 * p + 1);
  c.stiffness_nonzeros = c.dofs * 2 * overlap;
  const double quadrature_points = static_cast<double>(c.elements) * static_cast<double>((p + 1) * (p + 1));
  c.memory_lower_bound_bytes = static_cast<double>(c.stiffness_nonzeros) * kBytesPerNonzero +
                               quadrature_points * kStateDoublesPerQuadraturePoint * 8.0 +
                               static_cast<double>(c.dofs) * kVectorsPerDof * 8.0;
  return c;
}

double physical_memory_bytes() {
  return static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
}

nlohmann::json default_scene_json() {
  static const char* const kText =
#include "dry_default.json.inc"
      ;
  return json::parse(kText);
}

Scene scene_with_overrides(nlohmann::json json, const std::vector<std::string>& overrides, const std::string& source,
                           const std::string& base_directory) {
  for (const auto& assignment : overrides) apply_override(json, assignment);
  return parse_scene(json, source, base_directory);
}

Scene scene_with_values(const Scene& scene, const std::vector<SceneValue>& values) {
  nlohmann::json json = scene.effective;
  for (const auto& [key, value, kind] : values) {
    // Written to the last bit: %.17g reads back to the same double, and an SI unit scales by 1.
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", value);
    std::string assignment = std::string(key) + "=";
    if (kind == QuantityKind::dimensionless) {
      assignment += text;
    } else {
      assignment += "\"" + std::string(text) + std::string(si_unit(kind)) + "\"";
    }
    apply_override(json, assignment);
  }
  return parse_scene(json, scene.source, scene.base_directory);
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  if (path.empty()) return scene_with_overrides(default_scene_json(), overrides, "default dry scene");
  const std::string base = std::filesystem::path(path).parent_path().string();
  return scene_with_overrides(read_scene_json(path), overrides, path, base.empty() ? "." : base);
}

}  // namespace mufric::scene
