#include "surrogate/reduction/tribometer.hpp"

#include <cmath>
#include <filesystem>
#include <numbers>

#include <Eigen/Dense>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/numpy_random.hpp"
#include "common/wording.hpp"
#include "surrogate/reduction/setup_fields.hpp"

namespace mufric {
using namespace reduction_setup;

double sphere_ploughing_coefficient(double x) {
  if (!(x > 0.0 && x <= 1.0)) throw Error("sphere_ploughing_coefficient: a/R must lie in (0, 1]");
  const double inverse = 1.0 / x;
  return 2.0 / std::numbers::pi * (inverse * inverse * std::asin(x) - std::sqrt(std::max(0.0, inverse * inverse - 1.0)));
}

std::vector<TribometerEstimate> friction_from_tribometer(const std::vector<TribometerTest>& tests, const TribometerSetup& setup) {
  if (!(setup.pin_radius > 0.0)) throw Error("tribometer setup: pin_radius must be positive");
  if (setup.draws < 2) throw Error("tribometer setup: draws must be at least 2");
  NumpyRandom rng(setup.seed);
  std::vector<TribometerEstimate> out;
  for (const auto& test : tests) {
    if (!(test.normal_force > 0.0)) throw Error(test.row_name + ": the normal force must be positive");
    if (!(test.sliding_velocity > 0.0)) throw Error(test.row_name + ": the sliding velocity must be positive");
    if (!(test.mu_apparent.mean > 0.0) || !(test.mu_apparent.standard_error > 0.0))
      throw Error(test.row_name + ": the apparent friction coefficient and its uncertainty must be positive");
    const ValueRange pressure_range =
        test.contact_pressure ? ValueRange{*test.contact_pressure, *test.contact_pressure} : setup.flow_pressure;
    if (!(pressure_range.low > 0.0) || pressure_range.high < pressure_range.low)
      throw Error(test.row_name + ": no contact pressure: give the setup's flow_pressure or a contact_pressure column");
    Eigen::ArrayXd mu_apparent(setup.draws), pressure(setup.draws);
    for (int d = 0; d < setup.draws; ++d) mu_apparent(d) = test.mu_apparent.mean + test.mu_apparent.standard_error * rng.standard_normal();
    for (int d = 0; d < setup.draws; ++d) pressure(d) = rng.uniform(pressure_range.low, pressure_range.high);
    // F_n = p π a² / 2: the front half of the contact circle carries the load (Goddard & Wilman).
    const Eigen::ArrayXd radius = (2.0 * test.normal_force / (std::numbers::pi * pressure)).sqrt();
    if (radius.maxCoeff() >= setup.pin_radius)
      throw Error(test.row_name + text_printf(": the contact's radius (%.3g mm at the lowest pressure) reaches the pin's "
                                                "(%.3g mm): the pin would sink in up to its equator; check the force, the "
                                                "pin_radius and the flow_pressure",
                                                radius.maxCoeff() * 1e3, setup.pin_radius * 1e3));
    Eigen::ArrayXd ploughing = Eigen::ArrayXd::Zero(setup.draws);
    if (setup.ploughing == PloughingCorrection::goddard_wilman)
      for (int d = 0; d < setup.draws; ++d) ploughing(d) = sphere_ploughing_coefficient(radius(d) / setup.pin_radius);
    TribometerEstimate e;
    e.group = test.group;
    e.sliding_velocity = test.sliding_velocity;
    e.mu_apparent = monte_carlo_estimate(mu_apparent);
    e.mu_ploughing = monte_carlo_estimate(ploughing);
    e.mu = monte_carlo_estimate(mu_apparent - ploughing);
    e.contact_pressure = monte_carlo_estimate(pressure);
    e.contact_radius = monte_carlo_estimate(radius);
    e.temperature = test.temperature;
    e.row_name = test.row_name;
    if (!(e.mu.mean > 0.0))
      throw Error(test.row_name + text_printf(": the pin's ploughing (%.3f) takes all of the apparent friction (%.3f): the "
                                                "pin's radius or the flow pressure is wrong, or the test measured ploughing",
                                                e.mu_ploughing.mean, e.mu_apparent.mean));
    out.push_back(e);
  }
  return out;
}

TribometerStudy read_tribometer_study(const std::string& setup_path) {
  const nlohmann::json setup = read_setup(setup_path);
  TribometerStudy study;
  study.setup_path = setup_path;
  study.tests_path = tests_path_of(setup, setup_path);
  TribometerSetup& s = study.setup;
  s.pin_radius = quantity_field(setup, "pin_radius", QuantityKind::length, setup_path);
  const std::string ploughing = setup.value("ploughing", std::string("goddard-wilman"));
  if (ploughing == "goddard-wilman") {
    s.ploughing = PloughingCorrection::goddard_wilman;
  } else if (ploughing == "none") {
    s.ploughing = PloughingCorrection::none;
  } else {
    throw Error(setup_path + ": 'ploughing' is '" + ploughing + "'; it must be goddard-wilman (the sphere's ploughing taken "
                "out) or none (the rows keep the apparent mu, ploughing included)");
  }
  if (setup.contains("flow_pressure")) s.flow_pressure = quantity_range_field(setup, "flow_pressure", QuantityKind::pressure, setup_path);
  read_draws(setup, s);
  study.provenance = provenance_of(setup);
  study.analysis_file = setup.value("analysis_file", study.analysis_file);
  study.calibration_file = setup.value("calibration_file", study.calibration_file);

  const Uncertainty errors = uncertainty_of(setup, setup_path);
  const std::string velocity = column_of(setup, "sliding_velocity", "sliding_velocity");
  const std::string force = column_of(setup, "normal_force", "normal_force");
  const std::string mu = column_of(setup, "mu", "mu");
  const std::string mu_uncertainty = column_of(setup, "mu_uncertainty", "mu" + suffix_of(errors.kind));
  std::vector<std::string> names{velocity, force, mu, mu_uncertainty};
  const auto optional_column = [&](const std::string& role) {
    return setup.contains("columns") && setup["columns"].contains(role) ? setup["columns"][role].get<std::string>() : std::string();
  };
  const std::string pressure = optional_column("contact_pressure"), temperature = optional_column("temperature"),
                    temperature_sd = optional_column("temperature_sd");
  study.groups = groups_of(setup);
  for (const auto& name : {pressure, temperature, temperature_sd, study.groups.column})
    if (!name.empty()) names.push_back(name);
  const CsvTable table = read_csv_columns(study.tests_path, names);
  const auto velocities = table.si_column(velocity, QuantityKind::velocity);
  const double force_unit = force_scale(table, force);
  std::vector<double> pressures, temperatures, temperature_sds;
  if (!pressure.empty()) pressures = table.si_column(pressure, QuantityKind::pressure);
  if (!temperature.empty()) temperatures = table.si_column(temperature, QuantityKind::temperature);
  if (!temperature_sd.empty()) temperature_sds = table.si_difference_column(temperature_sd, QuantityKind::temperature);
  name_groups(study.groups, table, setup);
  const std::string file = std::filesystem::path(study.tests_path).filename().string();
  for (size_t i = 0; i < table.rows.size(); ++i) {
    TribometerTest t;
    t.group = group_of_row(study.groups, table, i);
    t.sliding_velocity = velocities[i];
    t.normal_force = force_unit * table.rows[i][table.column(force)];
    t.mu_apparent = {table.rows[i][table.column(mu)], errors.standard_error(table.rows[i][table.column(mu_uncertainty)])};
    if (!pressures.empty()) t.contact_pressure = pressures[i];
    if (!temperatures.empty()) t.temperature = MeasuredMean{temperatures[i], temperature_sds.empty() ? 0.0 : temperature_sds[i]};
    t.row_name = file + " line " + std::to_string(table.line_of_row[i]);
    study.tests.push_back(t);
  }
  if (study.tests.empty()) throw Error(study.tests_path + ": no test rows");
  if (pressures.empty() && !(s.flow_pressure.low > 0.0))
    throw Error(setup_path + ": no 'flow_pressure' and no contact_pressure column: the contact's pressure and radius need one");
  return study;
}

std::vector<WrittenTable> tribometer_tables(const TribometerStudy& study, const std::vector<TribometerEstimate>& results) {
  const std::string draws = draws_sentence(study.setup.draws, study.setup.seed);
  const bool corrected = study.setup.ploughing == PloughingCorrection::goddard_wilman;
  const bool temperatures = !results.empty() && results.front().temperature.has_value();
  auto pair = [](const McEstimate& e, double scale) { return g_text(e.mean * scale, 6) + "," + g_text(e.sd * scale, 4); };
  std::string analysis = comment_block(study.provenance);
  analysis += "# " + draws + (corrected ? " mu: the apparent mu less the pin's ploughing (Goddard & Wilman 1962)."
                                        : " No ploughing correction: mu is the apparent mu, the pin's ploughing included.") + "\n";
  analysis += study.groups.header_cell() +
              std::string("row,sliding_velocity[m/min],mu_apparent,mu_apparent_sd,mu_ploughing,mu_ploughing_sd,mu,mu_sd,"
                          "contact_pressure[MPa],contact_pressure_sd[MPa],contact_radius[um],contact_radius_sd[um]\n");
  for (const auto& r : results) {
    analysis += (study.groups.header.empty() ? "" : g_text(r.group, 6) + ",") + "\"" + r.row_name + "\"," +
                g_text(r.sliding_velocity * 60.0, 6) + "," + pair(r.mu_apparent, 1.0) + "," + pair(r.mu_ploughing, 1.0) + "," +
                pair(r.mu, 1.0) + "," + pair(r.contact_pressure, 1e-6) + "," + pair(r.contact_radius, 1e6) + "\n";
  }
  std::vector<WrittenTable> out{{study.analysis_file, analysis}};
  for (double group : groups_in_order(results)) {
    if (!study.groups.calibrates(group)) continue;
    std::string text = comment_block(study.provenance);
    text += "# " + with_value(study.groups.label, group) + "; one row per test. " + draws +
            (corrected ? " mu less the pin's ploughing." : " mu apparent (ploughing included).") + "\n";
    text += std::string("contact_pressure[MPa],contact_pressure_sd[MPa],sliding_velocity[m/min],") +
            (temperatures ? "temperature[C],temperature_sd[C]," : "") + "mu,mu_sd\n";
    for (const auto& r : results) {
      if (r.group != group) continue;
      text += pair(r.contact_pressure, 1e-6) + "," + g_text(r.sliding_velocity * 60.0, 6) + ",";
      if (temperatures) text += g_text(r.temperature->mean - kCelsiusOffset, 6) + "," + g_text(r.temperature->standard_error, 4) + ",";
      text += pair(r.mu, 1.0) + "\n";
    }
    out.push_back({with_value(study.calibration_file, group), text});
  }
  return out;
}

std::string tribometer_summary(const TribometerStudy& study, const std::vector<TribometerEstimate>& results) {
  std::string text;
  for (const auto& r : results)
    text += text_printf("%s, %s: v %6.3g m/min, mu apparent %.3f +- %.3f, ploughing %.3f, mu %.3f +- %.3f, p %5.0f MPa, a %.3g um\n",
                        with_value(study.groups.label, r.group).c_str(), r.row_name.c_str(), r.sliding_velocity * 60.0,
                        r.mu_apparent.mean, r.mu_apparent.sd, r.mu_ploughing.mean, r.mu.mean, r.mu.sd,
                        r.contact_pressure.mean * 1e-6, r.contact_radius.mean * 1e6);
  return text;
}

}  // namespace mufric
