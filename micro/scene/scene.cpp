#include "micro/scene/scene.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <fstream>
#include <set>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
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

// contact: the module's own options, then what depends on the rest of the scene.
void read_contact(Section c, Scene& s) {
  s.contact = contact::ContactOptions::read(c, s.base_directory);
  const bool frictional = s.contact.interface.law->frictional();
  const std::string law_name(s.contact.interface.law->name());
  // Wetted spots take the law's wetted coefficients (contact::kDefaultWetted* say where the defaults
  // come from); only a lubricated scene has a film to wet them.
  if (c.has("wetted") && frictional && s.physics != Physics::lubricated) {
    c.report().warn("contact.wetted is read but has no effect: the scene's physics is dry (no film wets a spot)");
  }
  if (frictional && !s.thermal.conducts()) {
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

// discretisation and material: the solid module's.
void read_discretisation(Section d, Scene& s) {
  s.discretisation = solid::ChipDiscretisation::read(d);
  d.finish();
}

void read_material(Section m, Scene& s) {
  s.material = solid::read_johnson_cook(m);
  m.finish();
}

// load: what drives Γ_B (a pressure or a vertical displacement, the sliding velocity, the ramp) and the
// chip's state as it arrives (its temperature and equivalent plastic strain).
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
  s.initial_plastic_strain = l.number("initial_plastic_strain", s.initial_plastic_strain, 0.0, 20.0);
  s.ramp = l.quantity("ramp", QuantityKind::time, s.ramp, 0.0, 1.0);
  l.finish();
}

// time: the time integration (the solid module's) and seed 000's run length and averaging window.
void read_time(Section t, Scene& s) {
  s.time = solid::TimeOptions::read(t);
  s.duration = t.quantity("duration", QuantityKind::time, s.duration, 1e-15, 10.0);
  if (s.time.dt > s.duration) t.fail("step", "is longer than the duration");
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
    if (s.time.scheme != solid::TimeScheme::generalized_alpha && s.pressure_controlled) {
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

// thermal and solver: the solid module's; lubricant: the coupling's (read by lubricated runs only).
void read_thermal(Section h, Scene& s) {
  s.thermal = solid::ThermalOptions::read(
      h, s.protocol.name == Protocol::seed000 ? solid::ThermalModel::adiabatic : solid::ThermalModel::conduction);
  h.finish();
}

void read_lubricant(Section f, Scene& s) {
  s.lubricant = coupling::LubricantSettings::read(f, s.protocol.name == Protocol::press_slide);
  f.finish();
}

void read_solver(Section v, Scene& s) {
  s.newton = solid::NewtonOptions::read(v);
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
                  s.discretisation.elements_x, s.discretisation.elements_y, s.discretisation.degree, cost.dofs,
                  cost.memory_lower_bound_bytes / 1e9,
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
  read_contact(root.child("contact"), s);
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
  s.keys_read = report.reads;
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
  const auto p = static_cast<long long>(scene.discretisation.degree);
  c.elements = static_cast<long long>(scene.discretisation.elements_x) * scene.discretisation.elements_y;
  c.dofs = 2LL * scene.discretisation.elements_x * (scene.discretisation.elements_y + p);
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

ComposedScene compose_scene(nlohmann::json base, const std::string& base_source, const std::vector<NamedPatch>& patches,
                            const std::vector<std::string>& overrides, const std::string& base_directory) {
  ComposedScene out;
  // Where each leaf value ("/material/a") came from: the base, or the last part that set it.
  std::map<std::string, std::string> leaf_source;
  // (flatten() returns a new object: kept in a variable, since a range over a temporary's items()
  // outlives it.)
  const nlohmann::json base_leaves = base.flatten();
  for (const auto& [pointer, value] : base_leaves.items()) leaf_source[pointer] = base_source;
  out.json = std::move(base);
  for (const NamedPatch& patch : patches) {
    if (!patch.json.is_object()) throw Error(patch.source + ": a scene part must be a JSON object of sections, e.g. {\"material\": {...}}");
    const nlohmann::json patch_leaves = patch.json.flatten();
    for (const auto& [pointer, value] : patch_leaves.items()) leaf_source[pointer] = patch.source;
    out.json.merge_patch(patch.json);
  }
  for (const auto& assignment : overrides) {
    apply_override(out.json, assignment);
    std::string pointer = "/" + assignment.substr(0, assignment.find('='));
    std::replace(pointer.begin(), pointer.end(), '.', '/');
    leaf_source[pointer] = "--set";
  }
  out.scene = parse_scene(out.json, patches.empty() ? base_source : patches.back().source, base_directory);
  // Per section, its keys by source: "material: a, b, ... from PART; heat_fraction from BASE".
  std::map<std::string, std::map<std::string, std::vector<std::string>>> keys_by_section;
  const nlohmann::json leaves = out.json.flatten();
  for (const auto& [pointer, value] : leaves.items()) {
    const auto second = pointer.find('/', 1);
    const std::string section = pointer.substr(1, second == std::string::npos ? std::string::npos : second - 1);
    const std::string key = second == std::string::npos ? section : pointer.substr(second + 1);
    const auto found = leaf_source.find(pointer);
    keys_by_section[section][found == leaf_source.end() ? std::string("--set") : found->second].push_back(key);
  }
  for (const auto& [section, sources] : keys_by_section) {
    std::string note = section + ":";
    bool first = true;
    for (const auto& [source, keys] : sources) {
      note += first ? " " : "; ";
      first = false;
      if (sources.size() == 1) {
        note += "from " + source;
        continue;
      }
      for (size_t i = 0; i < keys.size(); ++i) {
        if (i) note += ", ";
        note += keys[i];
      }
      note += " from " + source;
    }
    out.notes.push_back(note);
  }
  const auto& tool = out.json["geometry"]["tool_surface"];
  if (tool.contains("synthetic")) {
    const auto& s = tool["synthetic"];
    out.notes.push_back("the tool's surface is synthetic (Ra " + s.value("ra", std::string("?")) + ", correlation length " +
                        s.value("correlation_length", std::string("?")) + ", from " + leaf_source["/geometry/tool_surface/synthetic/ra"] +
                        "), not a measured profile: give one by geometry.tool_surface.csv (`mufric micro profile` fits it)");
  }
  return out;
}

const std::vector<SettableInput>& settable_inputs() {
  static const std::vector<SettableInput> inputs = [] {
    std::vector<SettableInput> list{{input_name::contact_pressure, "load.pressure", QuantityKind::pressure},
                                    {input_name::sliding_velocity, "load.velocity", QuantityKind::velocity},
                                    {input_name::temperature, "load.temperature", QuantityKind::temperature}};
    for (const contact::CoefficientInput& c : contact::coefficient_inputs()) {
      list.push_back({c.input, "contact." + std::string(c.key), kind_of_input(c.input)});
    }
    return list;
  }();
  return inputs;
}

const SettableInput* find_settable_input(std::string_view input) {
  for (const SettableInput& s : settable_inputs()) {
    if (s.input == input) return &s;
  }
  return nullptr;
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
