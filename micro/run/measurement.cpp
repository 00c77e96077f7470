#include "micro/run/measurement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>

#include <omp.h>

#include "common/environment.hpp"
#include "common/error.hpp"
#include "common/work_pool.hpp"

namespace mufric::run {
using namespace scene;

std::vector<Draw> protocol_draws(const Scene& scene) {
  if (scene.protocol.name == Protocol::seed000) return {Draw{0, 0, 0.0, scene.tool_surface.synthetic.seed, {}, {}}};
  std::vector<Draw> draws;
  const int phases = scene.protocol.phases, realisations = scene.protocol.realisations;
  const bool chip_drawn = scene.protocol.draws == DrawnSurfaces::tools_and_chip;
  for (int r = 0; r < realisations; ++r) {
    const auto offset = static_cast<std::uint64_t>(r);
    for (int k = 0; k < phases; ++k) {
      Draw d{k, r, static_cast<double>(k) / phases, scene.tool_surface.synthetic.seed + offset, {}, {}};
      if (chip_drawn) d.chip_seed = scene.chip_surface.synthetic.seed + offset;
      draws.push_back(d);
    }
  }
  return draws;
}

Scene draw_scene(const Scene& scene, const Draw& draw) {
  Scene s = scene;
  // A shift by a whole interval is no shift: keep the fraction in [0, 1).
  const double shift = scene.tool_surface.shift_fraction + draw.shift_fraction;
  s.tool_surface.shift_fraction = shift - std::floor(shift);
  s.tool_surface.synthetic.seed = draw.seed;
  if (draw.chip_seed) s.chip_surface.synthetic.seed = *draw.chip_seed;
  return s;
}

MeasurementTotals MuMeasurement::totals() const {
  MeasurementTotals t;
  for (const auto& d : draws) {
    t.newton_iterations += d.result.solver.newton_iterations;
    t.cutbacks += static_cast<int>(d.result.solver.cutbacks.size());
    if (d.result.lubricant) t.coupling_iterations += d.result.lubricant->coupling_iterations;
    t.max_contact_pressure = std::max(t.max_contact_pressure, d.result.max_contact_pressure);
    t.max_plastic_strain = std::max(t.max_plastic_strain, d.result.max_plastic_strain);
    t.max_temperature = std::max(t.max_temperature, d.result.max_temperature);
    t.contact_fraction += d.result.contact_fraction / static_cast<double>(draws.size());
    t.draw_seconds_sum += d.result.wall_seconds;
  }
  if (!draws.empty()) t.dofs = draws.front().result.dofs;
  return t;
}

namespace {

constexpr std::pair<const char*, int MeasurementTotals::*> kTotalsCounts[] = {
    {"newton_iterations", &MeasurementTotals::newton_iterations},
    {"coupling_iterations", &MeasurementTotals::coupling_iterations},
    {"cutbacks", &MeasurementTotals::cutbacks},
    {"dofs", &MeasurementTotals::dofs}};
constexpr std::pair<const char*, double MeasurementTotals::*> kTotalsValues[] = {
    {"max_contact_pressure_pa", &MeasurementTotals::max_contact_pressure},
    {"max_plastic_strain", &MeasurementTotals::max_plastic_strain},
    {"max_temperature_k", &MeasurementTotals::max_temperature},
    {"contact_area_fraction", &MeasurementTotals::contact_fraction}};

}  // namespace

nlohmann::json MeasurementTotals::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, field] : kTotalsCounts) j[name] = this->*field;
  for (const auto& [name, field] : kTotalsValues) j[name] = this->*field;
  return j;
}

std::map<std::string, double> MeasurementTotals::named_values() const {
  std::map<std::string, double> values;
  for (const auto& [name, field] : kTotalsCounts) values[name] = static_cast<double>(this->*field);
  for (const auto& [name, field] : kTotalsValues) values[name] = this->*field;
  return values;
}

double MuMeasurement::max_abs_drift() const {
  double d = 0.0;
  for (const auto& draw : draws) d = std::max(d, std::abs(draw.result.drift));
  return d;
}

void add_measurement_advisories(MuMeasurement& m) {
  const double n = static_cast<double>(m.draws.size());
  for (size_t i = 0; i < m.draws.size(); ++i) {
    const double drift = m.draws[i].result.drift;
    if (std::abs(drift) > kDriftWarningFraction) {
      char text[256];
      std::snprintf(text, sizeof text,
                    "draw %zu: mu drifted by %.1f %% of mu across its averaging window (first to last block mean, "
                    "warning above %.0f %%): the slide may not be steady; a longer protocol.window or more draws",
                    i, 100.0 * drift, 100.0 * kDriftWarningFraction);
      m.advisories.emplace_back(text);
    }
  }
  if (m.draws.size() > 1 && m.draws.size() < kFewDrawsForStdError) {
    // The relative standard error of a sample standard deviation from n draws is ≈ 1/√(2(n − 1))
    // (normal draws; Kendall & Stuart, The Advanced Theory of Statistics, Vol. 1, §10.8).
    char text[256];
    std::snprintf(text, sizeof text,
                  "the standard error of mu comes from %zu draws: it is itself uncertain by about +-%.0f %%; "
                  "%zu or more draws make it a figure to rely on",
                  m.draws.size(), 100.0 / std::sqrt(2.0 * (n - 1.0)), kFewDrawsForStdError);
    m.advisories.emplace_back(text);
  }
}

MuMeasurement measure_mu(const Scene& scene, const MeasureOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MuMeasurement m;
  m.draws = protocol_draws(scene);
  const int cores = std::max(options.threads > 0 ? options.threads : usable_cores(), 1);
  const int workers = std::min(cores, static_cast<int>(m.draws.size()));
  m.threads = workers;
  // Draws are independent runs: one per worker, each worker's OpenMP share of the cores for its
  // assembly (a single draw gets them all).
  const int threads_per_draw = std::max(cores / workers, 1);
  std::mutex progress_lock;
  std::vector<std::string> failures(m.draws.size());
  run_work_pool(m.draws.size(), workers, [&](size_t i) {
    omp_set_num_threads(threads_per_draw);
    RunOptions run;
    if (i == 0) run.vtu_directory = options.vtu_directory;
    if (options.wall_seconds_limit > 0.0) {
      run.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(options.wall_seconds_limit));
      run.wall_seconds_limit = options.wall_seconds_limit;
    }
    if (options.on_step) {
      run.on_step = [&, i](const MicroStep& step, const Scene& sc) {
        const std::lock_guard<std::mutex> lock(progress_lock);
        options.on_step(static_cast<int>(i), step, sc);
      };
    }
    try {
      m.draws[i].result = run_micro(draw_scene(scene, m.draws[i]), run);
    } catch (const std::exception& e) {  // a bad scene fails every draw alike: reported once below
      failures[i] = e.what();
    }
    return true;
  });
  for (size_t i = 0; i < failures.size(); ++i) {
    if (!failures[i].empty()) throw Error(failures[i]);
  }

  std::vector<double> values;
  for (const auto& draw : m.draws) {
    const MicroResult& r = draw.result;
    for (const auto& w : r.warnings) {
      if (std::find(m.warnings.begin(), m.warnings.end(), w) == m.warnings.end()) m.warnings.push_back(w);
    }
    if (!r.completed && m.reason.empty()) {
      m.reason = m.draws.size() == 1 ? r.reason
                                     : "draw " + std::to_string(&draw - m.draws.data()) + " (tool phase " +
                                           std::to_string(draw.phase) + ", realisation " +
                                           std::to_string(draw.realisation) + ") did not complete: " + r.reason;
    }
    values.push_back(r.mu);
  }
  if (m.reason.empty()) {
    m.completed = true;
    const double n = static_cast<double>(values.size());
    m.mu = std::accumulate(values.begin(), values.end(), 0.0) / n;
    if (values.size() > 1) {
      double squares = 0.0;
      for (double x : values) squares += (x - m.mu) * (x - m.mu);
      m.std_error = std::sqrt(squares / (n - 1.0) / n);  // sample standard deviation / √n
    }
    add_measurement_advisories(m);
  }
  m.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m;
}

nlohmann::json MuMeasurement::to_json(const Scene& scene) const {
  std::vector<std::string> all_warnings = warnings;
  all_warnings.insert(all_warnings.end(), advisories.begin(), advisories.end());
  nlohmann::json j = result_head(scene, true, completed, reason, all_warnings, mu);
  j["mu_std_error"] = completed && std_error ? nlohmann::json(*std_error) : nlohmann::json(nullptr);
  const ProtocolSpec& q = scene.protocol;
  nlohmann::json& p = j["protocol"];
  if (q.name == Protocol::seed000) {
    p = {{"name", "seed-000"},
         {"means", "one draw; pressure ramped over load.ramp while sliding; mu averaged over a time window"},
         {"window_s", {scene.average_from, scene.duration}},
         {"draws", draws.size()}};
  } else {
    p = {{"name", "press-slide"},
         {"means", "pressed (ramp, then hold), then slid; mu averaged over a sliding-distance window after a run-in, "
                   "then over the draws (tool phases and realisations, each realisation a new tool and, with drawn_surfaces "
                   "tools-and-chip, a new chip surface); mu_std_error is the standard error of that mean"},
         {"press_ramp_s", scene.ramp},
         {"press_hold_s", q.press_hold},
         {"run_in_m", q.run_in},
         {"window_m", q.window},
         {"window_in_tool_correlation_lengths",
          scene.tool_surface.is_synthetic()
              ? nlohmann::json(q.window / scene.tool_surface.synthetic.correlation_length)
              : nlohmann::json(nullptr)},
         {"step_distance_m", q.step_distance},
         {"phases", q.phases},
         {"realisations", q.realisations},
         {"drawn_surfaces", choice_name(q.draws)},
         {"draws", draws.size()},
         {"max_abs_drift", max_abs_drift()}};
  }
  // Aggregates over the draws, for scripts that read one run.
  const MeasurementTotals t = totals();
  nlohmann::json& diagnostics = j["diagnostics"] = t.to_json();
  diagnostics["wall_seconds"] = wall_seconds;
  diagnostics["threads"] = threads;
  diagnostics["draw_seconds_sum"] = t.draw_seconds_sum;
  diagnostics["elements"] = draws.empty() ? 0 : draws.front().result.elements;
  // The work split, averaged over the draws like μ.
  double interface_sum = 0.0, plastic_sum = 0.0, normal_sum = 0.0;
  int split_draws = 0;
  for (const auto& d : draws) {
    const MicroResult& r = d.result;
    if (!r.mu_interface_work || !r.mu_plastic_work || !r.mu_normal_work) continue;
    interface_sum += *r.mu_interface_work;
    plastic_sum += *r.mu_plastic_work;
    normal_sum += *r.mu_normal_work;
    ++split_draws;
  }
  if (completed && split_draws == static_cast<int>(draws.size()) && split_draws > 0) {
    j["work_split"] = work_split_json(interface_sum / split_draws, plastic_sum / split_draws, normal_sum / split_draws);
  }
  auto& list = j["draws"] = nlohmann::json::array();
  for (const auto& d : draws) {
    nlohmann::json one = d.result.to_json(scene, false);
    one["phase"] = d.phase;
    one["realisation"] = d.realisation;
    one["tool_shift_fraction"] = d.shift_fraction;
    one["tool_seed"] = d.seed;
    one["chip_seed"] = d.chip_seed                        ? nlohmann::json(*d.chip_seed)
                       : scene.chip_surface.is_synthetic() ? nlohmann::json(scene.chip_surface.synthetic.seed)
                                                           : nlohmann::json(nullptr);
    if (!d.result.block_means.empty()) {
      one["block_means"] = d.result.block_means;
      one["drift"] = d.result.drift;
    }
    list.push_back(std::move(one));
  }
  return j;
}

}  // namespace mufric::run
