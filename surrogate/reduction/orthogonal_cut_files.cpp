#include "surrogate/reduction/orthogonal_cut_files.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>

#include <nlohmann/json.hpp>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/units.hpp"
#include "common/wording.hpp"
#include "surrogate/reduction/setup_fields.hpp"

namespace mufric {
using namespace reduction_setup;
namespace {


std::vector<OrthogonalCut> read_cuts(const nlohmann::json& setup, const std::string& setup_path, const std::string& tests_path,
                                     TestGroups& groups) {
  const Uncertainty errors = uncertainty_of(setup, setup_path);
  const UncertaintyKind kind = errors.kind;
  const std::string speed = column_of(setup, "cutting_speed", "cutting_speed");
  const std::string thickness = column_of(setup, "uncut_chip_thickness", "uncut_chip_thickness");
  std::map<std::string, std::pair<std::string, std::string>> measured;  // role → (mean column, uncertainty column)
  for (const std::string role : {"cutting_force", "feed_force", "chip_ratio"}) {
    const std::string mean = column_of(setup, role, role);
    measured[role] = {mean, column_of(setup, role + "_uncertainty", role + suffix_of(kind))};
  }
  std::vector<std::string> names{speed, thickness};
  for (const auto& [role, columns] : measured) names.insert(names.end(), {columns.first, columns.second});
  if (!groups.column.empty()) names.push_back(groups.column);
  CsvTable table;
  try {
    table = read_csv_columns(tests_path, names);
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + "; where the file's names differ, the setup " + setup_path +
                " names them in \"columns\" (roles: cutting_speed, uncut_chip_thickness, cutting_force, feed_force, "
                "chip_ratio, each also with _uncertainty)");
  }
  name_groups(groups, table, setup);
  const auto speeds = table.si_column(speed, QuantityKind::velocity);
  const auto thicknesses = table.si_column(thickness, QuantityKind::length);
  auto mean_of = [&](const std::string& role, size_t row) {
    const auto& [mean, uncertainty] = measured.at(role);
    const double scale = role == "chip_ratio" ? 1.0 : force_scale(table, mean);
    const double uncertainty_scale = role == "chip_ratio" ? 1.0 : force_scale(table, uncertainty);
    return MeasuredMean{scale * table.rows[row][table.column(mean)],
                        errors.standard_error(uncertainty_scale * table.rows[row][table.column(uncertainty)])};
  };
  const std::string file = std::filesystem::path(tests_path).filename().string();
  std::vector<OrthogonalCut> cuts;
  for (size_t i = 0; i < table.rows.size(); ++i) {
    OrthogonalCut cut;
    cut.group = group_of_row(groups, table, i);
    cut.cutting_speed = speeds[i];
    cut.uncut_chip_thickness = thicknesses[i];
    cut.cutting_force = mean_of("cutting_force", i);
    cut.feed_force = mean_of("feed_force", i);
    cut.chip_ratio = mean_of("chip_ratio", i);
    cut.row_name = file + " line " + std::to_string(table.line_of_row[i]);
    cuts.push_back(cut);
  }
  if (cuts.empty()) throw Error(tests_path + ": no test rows");
  return cuts;
}

// The thicknesses every speed was cut at, if they are the same everywhere.
std::optional<std::vector<double>> common_thicknesses(const std::vector<RakeFaceEstimate>& results) {
  for (const auto& r : results)
    if (r.thicknesses != results.front().thicknesses) return std::nullopt;
  return results.front().thicknesses;
}

std::string joined_um(const std::vector<double>& thicknesses) {
  std::string text;
  for (size_t i = 0; i < thicknesses.size(); ++i) {
    if (i) text += ", ";
    text += g_text(thicknesses[i] * 1e6, 6);
  }
  return text;
}

}  // namespace

OrthogonalCutStudy read_orthogonal_cut_study(const std::string& setup_path) {
  const nlohmann::json setup = read_setup(setup_path);
  OrthogonalCutStudy study;
  study.setup_path = setup_path;
  study.tests_path = tests_path_of(setup, setup_path);
  OrthogonalCutSetup& s = study.setup;
  s.rake_angle = quantity_field(setup, "rake_angle", QuantityKind::angle, setup_path);
  s.cut_width = quantity_field(setup, "cut_width", QuantityKind::length, setup_path);
  s.room_temperature = quantity_field(setup, "room_temperature", QuantityKind::temperature, setup_path);
  s.density = number_field(setup, "density_kg_per_m3", setup_path);
  s.conductivity = range_field(setup, "conductivity_W_per_m_K", setup_path);
  s.specific_heat = range_field(setup, "specific_heat_J_per_kg_K", setup_path);
  if (setup.contains("secondary_zone_ratio")) s.secondary_zone_ratio = range_field(setup, "secondary_zone_ratio", setup_path);
  read_draws(setup, s);
  study.groups = groups_of(setup);
  study.cuts = read_cuts(setup, setup_path, study.tests_path, study.groups);
  study.provenance = provenance_of(setup);
  study.analysis_file = setup.value("analysis_file", study.analysis_file);
  study.calibration_file = setup.value("calibration_file", study.calibration_file);
  return study;
}

std::vector<WrittenTable> orthogonal_cut_tables(const OrthogonalCutStudy& study, const std::vector<RakeFaceEstimate>& results) {
  const OrthogonalCutSetup& s = study.setup;
  const auto thicknesses = common_thicknesses(results);
  const std::string thin = thicknesses ? "temperature_at_" + g_text(thicknesses->front() * 1e6, 6) + "um" : "temperature_at_thinnest";
  const std::string thick = thicknesses ? "temperature_at_" + g_text(thicknesses->back() * 1e6, 6) + "um" : "temperature_at_thickest";
  struct Column {
    std::string name, unit;
    McEstimate RakeFaceEstimate::*estimate;
    double scale, offset;
  };
  const std::vector<Column> columns{
      {"mu", "", &RakeFaceEstimate::mu, 1.0, 0.0},
      {"contact_pressure", "MPa", &RakeFaceEstimate::contact_pressure, 1e-6, 0.0},
      {"sliding_velocity", "m/min", &RakeFaceEstimate::sliding_velocity, 60.0, 0.0},
      {"temperature", "C", &RakeFaceEstimate::temperature, 1.0, kCelsiusOffset},
      {thin, "C", &RakeFaceEstimate::temperature_thinnest, 1.0, kCelsiusOffset},
      {thick, "C", &RakeFaceEstimate::temperature_thickest, 1.0, kCelsiusOffset},
      {"chip_ratio", "", &RakeFaceEstimate::chip_ratio, 1.0, 0.0},
      {"shear_angle", "deg", &RakeFaceEstimate::shear_angle, 180.0 / std::numbers::pi, 0.0},
      {"contact_length_per_h", "", &RakeFaceEstimate::contact_length_per_h, 1.0, 0.0},
      {"C_neq", "", &RakeFaceEstimate::oxley_c_neq, 1.0, 0.0},
      {"specific_cutting_force", "MPa", &RakeFaceEstimate::specific_cutting_force, 1e-6, 0.0},
      {"specific_feed_force", "MPa", &RakeFaceEstimate::specific_feed_force, 1e-6, 0.0},
      {"edge_cutting_force", "N", &RakeFaceEstimate::edge_cutting_force, 1.0, 0.0},
      {"edge_feed_force", "N", &RakeFaceEstimate::edge_feed_force, 1.0, 0.0},
  };
  auto cell_pair = [](const McEstimate& e, double scale, double offset) {
    return g_text(e.mean * scale - offset, 6) + "," + g_text(e.sd * std::abs(scale), 4);
  };
  const std::string draws = draws_sentence(s.draws, s.seed);
  std::string analysis = comment_block(study.provenance);
  analysis += "# " + draws + " Temperatures in C (the mean over h = " +
              (thicknesses ? joined_um(*thicknesses) + " um and at " + g_text(thicknesses->front() * 1e6, 6) + " and " +
                                 g_text(thicknesses->back() * 1e6, 6) + " um)."
                           : "each speed's thicknesses and at its thinnest and thickest).") + "\n";
  std::string header = study.groups.header_cell() + "cutting_speed[m/min]";
  for (const auto& c : columns) {
    const std::string unit = c.unit.empty() ? "" : "[" + c.unit + "]";
    header += "," + c.name + unit + "," + c.name + "_sd" + unit;
  }
  header += ",birge_ratio_cutting_force,birge_ratio_cutting_force_sd,birge_ratio_feed_force,birge_ratio_feed_force_sd";
  analysis += header + "\n";
  for (const auto& r : results) {
    std::string line = study.groups.header.empty() ? "" : g_text(r.group, 6) + ",";
    line += g_text(r.cutting_speed * 60.0, 6);
    for (const auto& c : columns) line += "," + cell_pair(r.*(c.estimate), c.scale, c.offset);
    line += "," + g_text(r.birge_cutting, 6) + ",0," + g_text(r.birge_feed, 6) + ",0";
    analysis += line + "\n";
  }
  std::vector<WrittenTable> out{{study.analysis_file, analysis}};

  for (double group : groups_in_order(results)) {
    if (!study.groups.calibrates(group)) continue;
    std::string speeds, rows;
    for (const auto& r : results) {
      if (r.group != group) continue;
      if (!speeds.empty()) speeds += ", ";
      speeds += g_text(r.cutting_speed * 60.0, 6);
      rows += cell_pair(r.contact_pressure, 1e-6, 0.0) + "," + cell_pair(r.sliding_velocity, 60.0, 0.0) + "," +
              cell_pair(r.temperature, 1.0, kCelsiusOffset) + "," + cell_pair(r.mu, 1.0, 0.0) + "\n";
    }
    std::string text = comment_block(study.provenance);
    text += "# " + with_value(study.groups.label, group) + "; one row per cutting speed (" + speeds + " m/min, in that order). " +
            draws + "\n";
    text += "contact_pressure[MPa],contact_pressure_sd[MPa],sliding_velocity[m/min],sliding_velocity_sd[m/min],temperature[C],"
            "temperature_sd[C],mu,mu_sd\n" + rows;
    out.push_back({with_value(study.calibration_file, group), text});
  }
  return out;
}

std::string orthogonal_cut_summary(const OrthogonalCutStudy& study, const std::vector<RakeFaceEstimate>& results) {
  std::string text;
  for (const auto& r : results) {
    text += text_printf("%s, %5g m/min: mu %.3f +- %.3f, p %5.0f +- %4.0f MPa, v_chip %5.2f m/min, T %4.0f +- %3.0f C, l_c/h %.2f, "
                        "edges %.1f / %.1f N, Birge %.2f / %.2f\n",
                        with_value(study.groups.label, r.group).c_str(), r.cutting_speed * 60.0, r.mu.mean, r.mu.sd,
                        r.contact_pressure.mean * 1e-6, r.contact_pressure.sd * 1e-6, r.sliding_velocity.mean * 60.0,
                        r.temperature.mean - kCelsiusOffset, r.temperature.sd, r.contact_length_per_h.mean,
                        r.edge_cutting_force.mean, r.edge_feed_force.mean, r.birge_cutting, r.birge_feed);
    if (r.nonpositive_mu_draws > 0)
      text += text_printf("  (%d of %d draws give mu <= 0, in the tail of the forces' scatter: kept in the mean and SD)\n",
                          r.nonpositive_mu_draws, study.setup.draws);
  }
  return text;
}

}  // namespace mufric
