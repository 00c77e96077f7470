// `mufric micro profile / run / check / converge / fluid-check`: the micro-model's user-facing steps
// (surface profiles and their fit, one run dry or lubricated, its cost before it runs, mesh and
// protocol convergence, the flow solver's benchmark). The work is micro/'s; here flags are parsed.
#include <chrono>
#include <cmath>
#include <functional>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <memory>
#include <string>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "common/files.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"
#include "micro/fluid/cavity.hpp"
#include "micro/run/measurement.hpp"
#include "micro/scene/scene_keys.hpp"
#include "micro/spline/profile.hpp"

namespace mufric::app {
namespace {

struct ProfileOptions {
  std::string csv, period = "", length = "10um", ra = "0.2um", correlation = "1um", out;
  int samples = 512, degree = 3, control_points = 64;
  unsigned long long seed = 1;
};

double length_option(const std::string& text, const std::string& flag) {
  return parse_quantity(text, QuantityKind::length, flag);
}

// A periodic profile of period L cannot show a correlation length much above L/5: the longest one
// any zero-mean profile of that period shows is its lowest harmonic's, cos(2 pi x / L) = 1/e at
// x = 0.19 L, and the generator's Gaussian spectrum puts nearly all its power there once the
// requested length approaches L/5 (`--correlation 100um --length 10um` printed 1.9um, the period's
// figure, not the request's). Hence: the period covers at least this many correlation lengths.
constexpr double kMinimumCorrelationLengthsPerPeriod = 5.0;

// The correlation length is where the autocorrelation falls to 1/e; with samples farther apart than
// that, neighbouring samples are already uncorrelated, the spectrum is cut at the Nyquist frequency
// and the profile is white noise whose measured correlation length (about 0.6 spacings) says
// nothing about the request. Hence: at least one sample per correlation length.
void check_synthetic_profile(const spline::RoughnessSpec& spec, const ProfileOptions& o) {
  if (!(spec.length > 0.0) || !(spec.ra > 0.0) || !(spec.correlation_length > 0.0)) {
    throw Error("--length, --ra and --correlation must be positive (got " + o.length + ", " + o.ra + ", " +
                o.correlation + ")");
  }
  if (spec.length < kMinimumCorrelationLengthsPerPeriod * spec.correlation_length) {
    throw Error("--correlation " + o.correlation + " is too long for --length " + o.length +
                ": a periodic profile cannot show a correlation length above about a fifth of its period; give a "
                "--length of at least " +
                format_human(kMinimumCorrelationLengthsPerPeriod * spec.correlation_length, QuantityKind::length) +
                " or a --correlation of at most " +
                format_human(spec.length / kMinimumCorrelationLengthsPerPeriod, QuantityKind::length));
  }
  const double spacing = spec.length / spec.samples;
  if (spacing > spec.correlation_length) {
    const auto samples_needed = static_cast<long long>(std::ceil(spec.length / spec.correlation_length));
    throw Error("--samples " + std::to_string(spec.samples) + " over --length " + o.length + " puts samples " +
                format_human(spacing, QuantityKind::length) + " apart, farther than --correlation " + o.correlation +
                ": the roughness would not be resolved; give --samples of at least " + std::to_string(samples_needed));
  }
}

// The fit's own limits, checked before anything is printed and named by their options.
void check_profile_fit(const spline::Profile& profile, const ProfileOptions& o) {
  if (o.control_points < o.degree + 1) {
    throw Error("--control-points " + std::to_string(o.control_points) + " cannot carry --degree " +
                std::to_string(o.degree) + ": a periodic spline of degree d needs at least d + 1 control points");
  }
  if (static_cast<size_t>(o.control_points) >= profile.x.size()) {
    throw Error("--control-points " + std::to_string(o.control_points) + " needs more samples than that, " +
                (o.csv.empty() ? "--samples is " : o.csv + " has ") + std::to_string(profile.x.size()) +
                ": a least-squares fit needs fewer control points than data");
  }
}

void run_profile(const ProfileOptions& o) {
  spline::Profile profile;
  if (!o.csv.empty()) {
    profile = spline::read_profile_csv(o.csv, o.period.empty() ? 0.0 : length_option(o.period, "--period"));
  } else {
    spline::RoughnessSpec spec;
    spec.length = length_option(o.length, "--length");
    spec.ra = length_option(o.ra, "--ra");
    spec.correlation_length = length_option(o.correlation, "--correlation");
    spec.samples = o.samples;
    spec.seed = o.seed;
    check_synthetic_profile(spec, o);
    profile = spline::synthetic_rough_profile(spec);
  }
  check_profile_fit(profile, o);
  const auto r = spline::roughness_figures(profile);
  std::printf("profile %s: %zu samples over one period of %s\n", profile.source.c_str(), profile.x.size(),
              format_human(profile.period, QuantityKind::length).c_str());
  std::printf("  Ra %s  Rq %s  Rz %s  correlation length %s\n", format_human(r.ra, QuantityKind::length).c_str(),
              format_human(r.rq, QuantityKind::length).c_str(), format_human(r.rz, QuantityKind::length).c_str(),
              r.correlation_length > 0.0 ? format_human(r.correlation_length, QuantityKind::length).c_str()
                                         : "(longer than half the period)");
  const spline::ProfileFit fit = spline::fit_periodic_profile(profile, o.degree, o.control_points);
  std::printf("periodic spline fit, degree %d, %d control points: rms error %s, max error %s (%.2f %% of Rz)\n",
              o.degree, o.control_points, format_human(fit.rms_error, QuantityKind::length).c_str(),
              format_human(fit.max_error, QuantityKind::length).c_str(), r.rz > 0.0 ? 100.0 * fit.max_error / r.rz : 0.0);
  if (!o.out.empty()) {
    // Data and fitted curve side by side, for a plot: the curve at each datum's parameter.
    std::ostringstream out;
    out << "x[um],height[um],fit_x[um],fit_height[um]\n";
    out.precision(10);
    for (size_t k = 0; k < profile.x.size(); ++k) {
      const Eigen::Vector2d c = fit.curve.point(fit.parameters[k]);
      out << profile.x[k] * 1e6 << "," << profile.height[k] * 1e6 << "," << c.x() * 1e6 << "," << c.y() * 1e6 << "\n";
    }
    write_file_atomically(o.out, out.str());
    std::printf("wrote %s\n", o.out.c_str());
  }
}

struct RunCommandOptions {
  std::string scene_path, out = "mufric-micro-out";
  std::vector<std::string> overrides;
  bool quiet = false;
  double tolerance = 0.007;
  int max_levels = 4;
  std::string direction = "both";  // converge: which element counts each level doubles
  std::string parameter = "mesh";  // converge: what each level refines
};

scene::Scene load_scene(const RunCommandOptions& o) { return scene::load_scene(o.scene_path, o.overrides); }

std::string mu_text(const std::optional<double>& mu) {
  if (!mu) return "  (no contact)";
  char text[32];
  std::snprintf(text, sizeof text, "%8.4f", *mu);
  return text;
}

// Per-step progress, throttled for measurements of several draws running at once (one line per
// draw and second at most, and every line says which draw it is).
class Progress {
 public:
  explicit Progress(size_t draws) : last_(draws, std::chrono::steady_clock::time_point{}) {}
  void operator()(int draw, const run::MicroStep& s, const scene::Scene& sc) {
    const auto now = std::chrono::steady_clock::now();
    auto& last = last_[static_cast<size_t>(draw)];
    const size_t draws = last_.size();
    if (draws > 1 && now - last < std::chrono::seconds(1)) return;
    last = now;
    const std::string who = draws > 1 ? "draw " + std::to_string(draw + 1) + "/" + std::to_string(draws) + "  " : "";
    if (sc.protocol.name == scene::Protocol::seed000) {
      std::fprintf(stderr, "%st %7.1f ns / %.1f ns  mu %s  contact %5.1f %%  max p %8.1f MPa\n", who.c_str(),
                   s.time * 1e9, sc.duration * 1e9, mu_text(s.mu).c_str(), 100.0 * s.contact_fraction, s.max_pressure / 1e6);
    } else {
      const double total = sc.protocol.run_in + sc.protocol.window;
      std::fprintf(stderr, "%st %8.1f ns  %s %6.3f / %.3f um  mu %s  contact %5.1f %%  max p %8.1f MPa\n", who.c_str(),
                   s.time * 1e9, s.sliding_distance > 0.0 ? "slid" : "pressing, slid", s.sliding_distance * 1e6,
                   total * 1e6, mu_text(s.mu).c_str(), 100.0 * s.contact_fraction, s.max_pressure / 1e6);
    }
  }

 private:
  std::vector<std::chrono::steady_clock::time_point> last_;  // per draw: when it last printed
};

std::string relative_percent(double value, double mu) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%", 100.0 * value / std::max(std::abs(mu), 1e-300));
  return text;
}

void print_summary(const run::MuMeasurement& m, const scene::Scene& sc) {
  const scene::ProtocolSpec& q = sc.protocol;
  if (m.completed && q.name == scene::Protocol::seed000) {
    const auto& r = m.draws.front().result;
    std::printf("mu = %.5f  (seed 000 protocol: one draw, eq. 17 time-averaged over [%.1f, %.1f] ns, %d steps; no "
                "error bar)\n", m.mu, sc.average_from * 1e9, sc.duration * 1e9, r.averaged_steps);
  } else if (m.completed) {
    // One draw has no standard error: saying +- 0 would claim an exact μ.
    const std::string error_bar =
        m.std_error ? [&] {
          char text[96];
          std::snprintf(text, sizeof text, "+- %.5f (standard error, %s)", *m.std_error,
                        relative_percent(*m.std_error, m.mu).c_str());
          return std::string(text);
        }()
                    : std::string("(one draw: no standard error; protocol.realisations >= 2 gives one)");
    std::printf("mu = %.5f %s  press-slide protocol: mean of %s (%s x %s), each pressed %.0f + %.0f ns, then averaged over %.3f um of sliding after a %.3f um "
                "run-in; largest drift over a window %s\n",
                m.mu, error_bar.c_str(),
                count_of(static_cast<long long>(m.draws.size()), "draw", "draws").c_str(),
                count_of(q.phases, "tool phase", "tool phases").c_str(),
                count_of(q.realisations, "realisation", "realisations").c_str(), sc.ramp * 1e9, q.press_hold * 1e9, q.window * 1e6, q.run_in * 1e6,
                relative_percent(m.max_abs_drift(), 1.0).c_str());
    if (m.draws.size() > 1) {
      std::printf("| draw | tool shift | tool seed | chip seed | mu | block means | drift | steps | Newton | cut-backs | wall [s] |\n"
                  "|---|---|---|---|---|---|---|---|---|---|---|\n");
      for (size_t i = 0; i < m.draws.size(); ++i) {
        const auto& d = m.draws[i];
        std::string blocks;
        for (double b : d.result.block_means) {
          char t[16];
          std::snprintf(t, sizeof t, "%s%.4f", blocks.empty() ? "" : " ", b);
          blocks += t;
        }
        const std::string chip = d.chip_seed ? std::to_string(*d.chip_seed) : "scene's";
        std::printf("| %zu | %.3f | %llu | %s | %.5f | %s | %s | %zu | %d | %zu | %.1f |\n", i + 1, d.shift_fraction,
                    static_cast<unsigned long long>(d.seed), chip.c_str(), d.result.mu, blocks.c_str(),
                    relative_percent(d.result.drift, 1.0).c_str(), d.result.history.size(),
                    d.result.solver.newton_iterations, d.result.solver.cutbacks.size(), d.result.wall_seconds);
      }
    }
  } else {
    std::printf("run did not complete: %s\n", m.reason.c_str());
  }
  const auto& r = m.draws.front().result;
  std::printf("first draw: contact area %.1f %% of the interval, max contact pressure %s, max plastic strain %.4f, max "
              "temperature %s\n",
              100.0 * r.contact_fraction, format_human(r.max_contact_pressure, QuantityKind::pressure).c_str(),
              r.max_plastic_strain, format_human(r.max_temperature, QuantityKind::temperature).c_str());
  std::printf("%d elements, %d dofs; first draw: %zu steps, %d Newton iterations (%d assemblies, %d line-search "
              "reductions), %zu cut-backs, %.2f s (assembly %.2f s of which contact %.2f s, solve %.2f s, heat "
              "conduction %.2f s); all %s on %s: %.2f s\n",
              r.elements, r.dofs, r.history.size(), r.solver.newton_iterations, r.solver.assemblies,
              r.solver.line_search_reductions, r.solver.cutbacks.size(), r.wall_seconds, r.solver.seconds_assembly,
              r.solver.seconds_contact, r.solver.seconds_solve, r.solver.seconds_after_step,
              count_of(static_cast<long long>(m.draws.size()), "draw", "draws").c_str(),
              count_of(m.threads, "thread", "threads").c_str(),
              m.wall_seconds);
  for (size_t i = 0; i < m.draws.size(); ++i) {
    for (const auto& c : m.draws[i].result.solver.cutbacks) {
      std::printf("  draw %zu: cut-back at %.2f ns (dt %.3g s): %s\n", i + 1, c.time * 1e9, c.dt_failed, c.reason.c_str());
    }
  }
  for (const auto& w : m.warnings) std::printf("warning: %s\n", w.c_str());
  for (const auto& w : m.advisories) std::printf("warning: %s\n", w.c_str());
}

int run_command(const RunCommandOptions& o) {
  const scene::Scene sc = load_scene(o);
  std::filesystem::create_directories(o.out);
  run::MeasureOptions options;
  options.vtu_directory = o.out;
  Progress progress(run::protocol_draws(sc).size());
  if (!o.quiet) options.on_step = std::ref(progress);
  for (const auto& w : sc.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  run::MuMeasurement m = run::measure_mu(sc, options);
  m.advisories.insert(m.advisories.begin(), sc.warnings.begin(), sc.warnings.end());
  write_file_atomically(o.out + "/result.json", m.to_json(sc).dump(2) + "\n");
  print_summary(m, sc);
  std::printf("wrote %s/result.json, %s/chip.vtu, %s/tool.vtu, %s/contact.csv%s (first draw)\n", o.out.c_str(),
              o.out.c_str(), o.out.c_str(), o.out.c_str(), sc.physics == scene::Physics::lubricated ? (", " + o.out + "/film.vtu").c_str() : "");
  return m.completed ? 0 : 3;
}

void run_check(const RunCommandOptions& o) {
  const scene::Scene sc = load_scene(o);  // refuses a scene that cannot fit, with the estimate
  const scene::SceneCost cost = scene::estimate_scene_cost(sc);
  const scene::Scene reference = scene::load_scene("", {});
  const scene::SceneCost base = scene::estimate_scene_cost(reference);
  std::printf("%s: %s, %d x %d elements of degree %d\n", sc.source.c_str(), scene::choice_name(sc.physics), sc.discretisation.elements_x,
              sc.discretisation.elements_y, sc.discretisation.degree);
  std::printf("  %lld solid unknowns (%.3gx the default scene's %lld), %lld stiffness nonzeros\n", cost.dofs,
              static_cast<double>(cost.dofs) / static_cast<double>(base.dofs), base.dofs, cost.stiffness_nonzeros);
  std::printf("  memory: at least %.3g MB (stiffness, quadrature state, vectors; the factor comes on top), this machine "
              "has %.3g GB\n", cost.memory_lower_bound_bytes / 1e6, scene::physical_memory_bytes() / 1e9);
  std::printf("  %s per measurement; the default scene takes about 30 s per draw on one core here, and a step's "
              "cost grows faster than the unknowns\n",
              count_of(static_cast<long long>(run::protocol_draws(sc).size()), "draw", "draws").c_str());
  for (const auto& w : sc.warnings) std::printf("warning: %s\n", w.c_str());
}

// What a level of `micro converge` refines, and how the table names it.
std::string level_setting(const scene::Scene& sc, const std::string& parameter) {
  char text[64];
  if (parameter == "step") {
    std::snprintf(text, sizeof text, "%.4g nm", sc.protocol.step_distance * 1e9);
  } else if (parameter == "window") {
    std::snprintf(text, sizeof text, "%.4g um", sc.protocol.window * 1e6);
  } else if (parameter == "phases") {
    std::snprintf(text, sizeof text, "%d x %d", sc.protocol.phases, sc.protocol.realisations);
  } else {
    std::snprintf(text, sizeof text, "%d x %d", sc.discretisation.elements_x, sc.discretisation.elements_y);
  }
  return text;
}

void refine(scene::Scene& sc, const RunCommandOptions& o) {
  if (o.parameter == "step") {
    sc.protocol.step_distance *= 0.5;
  } else if (o.parameter == "window") {
    sc.protocol.window *= 2.0;
  } else if (o.parameter == "phases") {
    sc.protocol.phases *= 2;
  } else {
    if (o.direction != "y") sc.discretisation.elements_x *= 2;
    if (o.direction != "x") sc.discretisation.elements_y *= 2;
  }
}

int converge_command(const RunCommandOptions& o) {
  scene::Scene sc = load_scene(o);
  if (o.parameter != "mesh" && sc.protocol.name == scene::Protocol::seed000) {
    throw Error("--parameter " + o.parameter + " refines the press-slide protocol; this scene uses seed-000's");
  }
  const char* what = o.parameter == "mesh" ? "elements" : o.parameter == "step" ? "sliding step"
                     : o.parameter == "window" ? "window" : "phases x realisations";
  std::printf("| level | %s | dofs | mu | std error | change | wall [s] |\n|---|---|---|---|---|---|---|\n", what);
  std::optional<double> previous;
  for (int level = 0; level <= o.max_levels; ++level) {
    const run::MuMeasurement m = run::measure_mu(sc);
    const auto& r = m.draws.front().result;
    if (!m.completed) {
      std::printf("| %d | %s | %d | failed | | | %.2f |\n", level, level_setting(sc, o.parameter).c_str(), r.dofs, m.wall_seconds);
      std::printf("level %d did not complete: %s\n", level, m.reason.c_str());
      return 3;
    }
    const double change = previous ? std::abs(m.mu - *previous) / std::max(std::abs(m.mu), 1e-12) : 0.0;
    std::printf("| %d | %s | %d | %.5f | %s | %s | %.2f |\n", level, level_setting(sc, o.parameter).c_str(), r.dofs, m.mu,
                m.std_error ? relative_percent(*m.std_error, m.mu).c_str() : "",
                previous ? (std::to_string(100.0 * change).substr(0, 5) + " %").c_str() : "", m.wall_seconds);
    std::fflush(stdout);
    if (previous && change < o.tolerance) {
      std::printf("converged at level %d: mu changed by %.2f %% (< %.2f %%) from the previous level\n", level,
                  100.0 * change, 100.0 * o.tolerance);
      return 0;
    }
    previous = m.mu;
    refine(sc, o);
  }
  std::printf("not converged within %d refinements (tolerance %.2f %%)\n", o.max_levels, 100.0 * o.tolerance);
  return 3;
}

}  // namespace

struct FluidCheckOptions {
  double reynolds = 100.0;
  int elements = 64, degree = 2;
};

// The lid-driven cavity's centre lines as CSV on stdout (lengths per cavity side L, velocities per lid
// speed U), the solve's summary on stderr.
int fluid_check_cavity(const FluidCheckOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const fluid::CavityResult r = fluid::solve_cavity({o.reynolds, o.elements, o.degree});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ostringstream history;
  for (double h : r.report.residual_history) history << ' ' << h;
  std::fprintf(stderr, "lid-driven cavity, Re = %g, %d x %d elements of degree %d: %s in %d Newton iterations, %.2f s\n"
               "residual history:%s\n", o.reynolds, o.elements, o.elements, o.degree,
               r.report.converged ? "converged" : ("not converged: " + r.report.reason).c_str(), r.report.newton_iterations,
               seconds, history.str().c_str());
  if (!r.report.converged) return 3;
  std::printf("centre_line,x[L],y[L],velocity[U],ghia1982[U]\n");
  const auto row = [](const char* line, double x, double y, const fluid::CenterlineSample& s) {
    std::printf("%s,%.6f,%.6f,%.6f,%s\n", line, x, y, s.velocity, s.reference ? std::to_string(*s.reference).c_str() : "");
  };
  for (const auto& s : r.vertical) row("u_on_x=0.5", 0.5, s.position, s);
  for (const auto& s : r.horizontal) row("v_on_y=0.5", s.position, 0.5, s);
  if (r.max_deviation) std::fprintf(stderr, "largest |velocity - Ghia et al. 1982| = %.5f U (34 points)\n", *r.max_deviation);
  return 0;
}

namespace {

// A scene file argument and --set, as every subcommand that reads a scene takes them.
void add_scene_arguments(CLI::App* cmd, RunCommandOptions& o) {
  cmd->add_option("scene", o.scene_path, "Scene file (JSON); without it the default dry scene")->check(CLI::ExistingFile);
  cmd->add_option("--set", o.overrides, "Override a scene value, e.g. --set load.pressure=1300MPa (repeatable)");
}

// A command's exit code as the process's: CLI11 exits with a RuntimeError's code.
std::function<void()> exiting_with_code(std::function<int()> command) {
  return [command = std::move(command)] {
    const int code = command();
    if (code != 0) throw CLI::RuntimeError(code);
  };
}

}  // namespace

void add_micro_commands(CLI::App& app) {
  auto* micro = app.add_subcommand("micro", "The high-fidelity micro-model of the tool-chip contact zone");
  micro->require_subcommand(1);
  auto o = std::make_shared<ProfileOptions>();
  auto* profile = micro->add_subcommand(
      "profile", "Roughness of a surface profile (measured CSV or synthetic) and its periodic spline fit");
  auto* csv = profile->add_option("--csv", o->csv,
                                  "Measured profile: columns x and height with length units, e.g. x[um],height[nm]")
                  ->check(CLI::ExistingFile);
  profile->add_option("--period", o->period, "Period of the measured profile (default: sampled range + one spacing)")
      ->needs(csv);
  // The synthetic profile's options mean nothing beside a measured one: refused rather than ignored.
  profile->add_option("--length", o->length, "Synthetic: period")->capture_default_str()->excludes(csv);
  profile->add_option("--ra", o->ra, "Synthetic: arithmetic mean roughness Ra")->capture_default_str()->excludes(csv);
  profile->add_option("--correlation", o->correlation,
                      "Synthetic: correlation length (at most a fifth of --length, at least the sample spacing)")
      ->capture_default_str()->excludes(csv);
  profile->add_option("--samples", o->samples, "Synthetic: samples per period")->capture_default_str()
      ->check(CLI::Range(10, 1 << 20))->excludes(csv);
  profile->add_option("--seed", o->seed, "Synthetic: random seed")->capture_default_str()->excludes(csv);
  profile->add_option("--degree", o->degree, "Spline degree of the fit")->capture_default_str()->check(CLI::Range(1, 10));
  profile->add_option("--control-points", o->control_points, "Control points of the fit (one period)")
      ->capture_default_str()->check(CLI::Range(2, 100000));
  profile->add_option("--out", o->out, "CSV of the data and the fitted curve, for a plot");
  profile->footer("Without --csv a Gaussian random profile with a Gaussian autocorrelation is generated, scaled to\n"
                  "the requested Ra exactly. The fit is a periodic least-squares B-spline with chord-length\n"
                  "parameters; its error is the distance from each datum to the curve at the datum's parameter.");
  profile->callback([o] { run_profile(*o); });

  auto r = std::make_shared<RunCommandOptions>();
  auto* run = micro->add_subcommand("run", "One high-fidelity run, dry or lubricated: mu by eq. 17 with its history and diagnostics");
  add_scene_arguments(run, *r);
  run->add_option("--out", r->out, "Directory for result.json, chip.vtu, tool.vtu, contact.csv (and film.vtu when lubricated)")->capture_default_str();
  run->add_flag("--quiet", r->quiet, "No per-step progress on stderr");
  run->footer("The scene's protocol says what mu means. press-slide (the default): the chip is pressed, then slid;\n"
              "mu is averaged over protocol.window of sliding after protocol.run_in, for protocol.phases tool\n"
              "positions (x protocol.realisations tools of the same roughness; with protocol.draws tools-and-chip,\n"
              "the default for a synthetic chip, each realisation also draws the chip surface anew), run in parallel\n"
              "on the cores OMP_NUM_THREADS allows, and printed with its standard error and each draw's block means\n"
              "and drift; protocol.draws=tools keeps the scene's one chip surface for every draw.\n"
              "seed-000 (--set protocol.name=seed-000): the paper's one draw, pressure ramped while sliding, mu\n"
              "averaged over [time.average_from, time.duration].\n"
              "Exit code 0 when the run completed and mu was averaged, 3 when it did not (result.json says why),\n"
              "2 for a bad scene (the message names the key). The default scene is micro/scene/dry_default.json.");
  run->callback(exiting_with_code([r] { return run_command(*r); }));

  auto* keys = micro->add_subcommand("keys", "Every scene key: its type, the value an absent key takes, its range or words (Markdown)");
  keys->footer("Generated from the scene reader itself (the default dry scene read dry, lubricated and under\n"
               "seed 000's protocol, and the interface laws' registry); docs/usage.md's \"Scene keys\" is this output.");
  keys->callback([] { std::fputs(scene::scene_key_reference().c_str(), stdout); });

  struct SceneCommandOptions {
    std::string base, out;
    std::vector<std::string> parts, overrides;
  };
  auto composed = std::make_shared<SceneCommandOptions>();
  auto* scene_command = micro->add_subcommand(
      "scene",
      "A new pair's scene: a base scene with scene parts merged over it (a material's Johnson-Cook and thermal set as "
      "{\"material\": {...}, \"thermal\": {...}}) and --set overrides, every unit and range checked by reading it; "
      "writes the JSON and says where each section came from and what stayed a default");
  scene_command->add_option("base", composed->base, "Scene file to start from (default: the default dry scene; "
                                                   "micro/scene/ti6al4v_tin.json is a pair's)")
      ->check(CLI::ExistingFile);
  scene_command->add_option("--with", composed->parts, "A scene part (JSON) merged over the base, e.g. the material's set (repeatable, in order)")
      ->check(CLI::ExistingFile);
  scene_command->add_option("--set", composed->overrides, "Override a scene value after the parts, e.g. --set material.a=1485MPa (repeatable)");
  scene_command->add_option("--out", composed->out, "Where the scene is written")->required();
  scene_command->callback([composed] {
    const std::string base_source = composed->base.empty() ? std::string("the default dry scene") : composed->base;
    std::vector<scene::NamedPatch> parts;
    for (const auto& path : composed->parts) parts.push_back({path, scene::read_scene_json(path)});
    const std::string base_directory =
        composed->base.empty() ? std::string(".") : std::filesystem::path(composed->base).parent_path().string();
    const scene::ComposedScene result =
        scene::compose_scene(composed->base.empty() ? scene::default_scene_json() : scene::read_scene_json(composed->base),
                             base_source, parts, composed->overrides, base_directory.empty() ? "." : base_directory);
    write_file_atomically(composed->out, result.json.dump(2) + "\n");
    for (const auto& note : result.notes) std::printf("%s\n", note.c_str());
    std::printf("wrote %s (read back: every unit and range checked)\n", composed->out.c_str());
  });

  auto k = std::make_shared<RunCommandOptions>();
  auto* check = micro->add_subcommand("check", "What a scene costs before it runs: unknowns, nonzeros and a memory lower bound");
  add_scene_arguments(check, *k);
  check->footer("A scene whose lower bound exceeds the machine's memory is refused by every command that loads it.\n"
                "Exit code 2 for a scene that is invalid or cannot fit; 0 otherwise.");
  check->callback([k] { run_check(*k); });

  auto c = std::make_shared<RunCommandOptions>();
  auto* converge = micro->add_subcommand(
      "converge", "Refine the mesh (or the sliding step, the window, the number of tool phases) until mu changes by\n"
                  "less than the tolerance between levels; a table of mu, its standard error and the wall time");
  add_scene_arguments(converge, *c);
  converge->add_option("--tolerance", c->tolerance, "Relative change of mu that counts as converged")
      ->capture_default_str()->check(FiniteRange(1e-6, 1.0));
  converge->add_option("--parameter", c->parameter,
                       "What each level refines: mesh (doubles the elements, see --direction), step (halves\n"
                       "protocol.step_distance), window (doubles protocol.window) or phases (doubles\n"
                       "protocol.phases)")
      ->capture_default_str()->check(CLI::IsMember({"mesh", "step", "window", "phases"}));
  converge->add_option("--max-levels", c->max_levels, "Most refinements")
      ->capture_default_str()->check(CLI::Range(1, 8));
  converge->add_option("--direction", c->direction,
                       "Which element counts a level doubles: both, x (along the contact) or y (through the\n"
                       "thickness, graded towards the contact as the scene's grading says)")
      ->capture_default_str()->check(CLI::IsMember({"both", "x", "y"}));
  converge->footer("The paper refined the region near the contact until mu changed by less than 0.7 %. Doubling one\n"
                   "direction at a time shows which one the error comes from (bench/studies/dry_micro_model/README.md: mostly y for the\n"
                   "default scene). --parameter step / window / phases converge the press-slide protocol's own\n"
                   "choices the same way; every level prints mu with its standard error over the draws, and a change\n"
                   "below that error is noise, not convergence. Exit code 0 when converged, 3 when not or when a\n"
                   "level failed.");
  converge->callback(exiting_with_code([c] { return converge_command(*c); }));

  auto fc = std::make_shared<FluidCheckOptions>();
  auto* fluid_check = micro->add_subcommand("fluid-check", "Verify the lubricant's flow solver on a published benchmark");
  fluid_check->require_subcommand(1);
  auto* cavity = fluid_check->add_subcommand(
      "cavity", "Lid-driven cavity (steady): both centre lines as CSV, beside Ghia, Ghia & Shin (1982) at Re = 100");
  cavity->add_option("--reynolds", fc->reynolds, "Reynolds number U L / nu")->capture_default_str()->check(FiniteRange(1e-3, 1e4));
  cavity->add_option("--elements", fc->elements, "Elements per side")->capture_default_str()->check(CLI::Range(4, 512));
  cavity->add_option("--degree", fc->degree, "Spline degree of velocity and pressure")->capture_default_str()->check(CLI::Range(1, 4));
  cavity->footer("The unit square, lid speed 1, steady Navier-Stokes by the same stabilised solver the lubricant uses.\n"
                 "Columns: the centre line, the point (x, y) in cavity lengths L, the velocity across the line (u on\n"
                 "x = 0.5, v on y = 0.5) in lid speeds U, and Ghia et al.'s value where they tabulate it (Re = 100).\n"
                 "Above Re = 100 the solve is continued from Re = 100 in doublings. Exit code 0 when converged, 3 when\n"
                 "not (stderr says why).");
  cavity->callback(exiting_with_code([fc] { return fluid_check_cavity(*fc); }));
}

}  // namespace mufric::app
