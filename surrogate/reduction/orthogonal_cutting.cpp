#include "surrogate/reduction/orthogonal_cutting.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include <Eigen/Dense>

#include "common/error.hpp"

namespace mufric {
namespace {

// Oxley (1989): the mean interface temperature's share of the maximum rise; Boothroyd's partition
// changes form at R_T tan φ = 10.
constexpr double kOxleyPsi = 0.9;
constexpr double kBoothroydBranch = 10.0;


// sqrt(χ²/dof) of the weighted least-squares line through (h, mean) with these standard errors.
double birge_ratio(const Eigen::VectorXd& h, const Eigen::VectorXd& means, const Eigen::VectorXd& errors) {
  const Eigen::Index n = h.size();
  if (n < 3) return 1.0;
  const Eigen::VectorXd weights = errors.array().square().inverse();
  Eigen::MatrixXd design(n, 2);
  design.col(0).setOnes();
  design.col(1) = h;
  const Eigen::Matrix2d normal = design.transpose() * weights.asDiagonal() * design;
  const Eigen::Vector2d coefficients = normal.ldlt().solve(design.transpose() * (weights.array() * means.array()).matrix());
  const double chi2 = (weights.array() * (means - design * coefficients).array().square()).sum();
  return std::sqrt(chi2 / static_cast<double>(n - 2));
}

// Draws (rows) of the means at each thickness (columns): mean + scale · SE · N(0, 1), row after row
// as NumPy fills standard_normal((draws, n)).
Eigen::ArrayXXd draw_means(const std::vector<const OrthogonalCut*>& at, MeasuredMean OrthogonalCut::*quantity,
                           double scale, int draws, NumpyRandom& rng) {
  const Eigen::Index n = static_cast<Eigen::Index>(at.size());
  Eigen::ArrayXXd out(draws, n);
  for (int d = 0; d < draws; ++d)
    for (Eigen::Index j = 0; j < n; ++j) {
      const MeasuredMean& m = (*at[j]).*quantity;
      out(d, j) = m.mean + scale * m.standard_error * rng.standard_normal();
    }
  return out;
}

struct Line {
  Eigen::ArrayXd slope, intercept;
};

// Least-squares lines through (h, F) for every draw (a row of F).
Line line_fits(const Eigen::ArrayXd& h, const Eigen::ArrayXXd& forces) {
  const Eigen::ArrayXd centred = h - h.mean();
  const Eigen::ArrayXd row_means = forces.rowwise().mean();
  const Eigen::ArrayXd slope =
      ((forces.colwise() - row_means).matrix() * centred.matrix()).array() / centred.matrix().squaredNorm();
  return {slope, row_means - slope * h.mean()};
}

struct ThermalDraws {
  Eigen::ArrayXd delta, conductivity, specific_heat;
};

// Oxley's (1989) mean tool-chip interface temperature (K) of the chip-forming forces at thickness h.
Eigen::ArrayXd oxley_interface_temperature(const OrthogonalCutSetup& setup, double speed, double h,
                                           const Eigen::ArrayXd& k_c, const Eigen::ArrayXd& k_f,
                                           const Eigen::ArrayXd& chip_ratio, const Eigen::ArrayXd& phi,
                                           const Eigen::ArrayXd& contact_length, const ThermalDraws& thermal) {
  const double gamma = setup.rake_angle;
  const Eigen::ArrayXd force_c = k_c * h * setup.cut_width, force_f = k_f * h * setup.cut_width;
  const Eigen::ArrayXd shear_force = force_c * phi.cos() - force_f * phi.sin();
  const Eigen::ArrayXd shear_velocity = speed * std::cos(gamma) / (phi - gamma).cos();
  const Eigen::ArrayXd friction_force = force_c * std::sin(gamma) + force_f * std::cos(gamma);
  const Eigen::ArrayXd chip_velocity = speed / chip_ratio;
  const double mass_rate = setup.density * speed * h * setup.cut_width;
  const Eigen::ArrayXd thermal_number = setup.density * thermal.specific_heat * speed * h / thermal.conductivity;
  const Eigen::ArrayXd r_tan_phi = thermal_number * phi.tan();
  const Eigen::ArrayXd beta = (r_tan_phi > kBoothroydBranch)
                                  .select(0.3 - 0.15 * r_tan_phi.log10(), 0.5 - 0.35 * r_tan_phi.log10());
  const Eigen::ArrayXd rise_shear_zone = (1.0 - beta) * shear_force * shear_velocity / (mass_rate * thermal.specific_heat);
  const Eigen::ArrayXd rise_chip = friction_force * chip_velocity / (mass_rate * thermal.specific_heat);
  const Eigen::ArrayXd ratio = thermal_number * chip_ratio * h / contact_length;
  const Eigen::ArrayXd root = ratio.sqrt();
  const Eigen::ArrayXd rise_max = rise_chip * Eigen::pow(10.0, 0.06 - 0.195 * thermal.delta * root) * root;
  return setup.room_temperature + rise_shear_zone + kOxleyPsi * rise_max;
}

std::string speed_words(double speed) {
  char text[64];
  std::snprintf(text, sizeof text, "%g m/min", speed * 60.0);
  return text;
}

RakeFaceEstimate analyse_speed(const std::vector<const OrthogonalCut*>& at, const OrthogonalCutSetup& setup,
                               NumpyRandom& rng) {
  const double gamma = setup.rake_angle;
  const int draws = setup.draws;
  const Eigen::Index n = static_cast<Eigen::Index>(at.size());
  Eigen::VectorXd h(n);
  for (Eigen::Index j = 0; j < n; ++j) h(j) = at[j]->uncut_chip_thickness;
  auto scale_of = [&](MeasuredMean OrthogonalCut::*quantity) {
    Eigen::VectorXd means(n), errors(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      means(j) = ((*at[j]).*quantity).mean;
      errors(j) = ((*at[j]).*quantity).standard_error;
    }
    return std::max(1.0, birge_ratio(h, means, errors));
  };
  RakeFaceEstimate out;
  out.group = at.front()->group;
  out.cutting_speed = at.front()->cutting_speed;
  for (const auto* cut : at) {
    out.thicknesses.push_back(cut->uncut_chip_thickness);
    out.rows.push_back(cut->row_name);
  }
  out.birge_cutting = scale_of(&OrthogonalCut::cutting_force);
  const Eigen::ArrayXXd fc = draw_means(at, &OrthogonalCut::cutting_force, out.birge_cutting, draws, rng);
  out.birge_feed = scale_of(&OrthogonalCut::feed_force);
  const Eigen::ArrayXXd ff = draw_means(at, &OrthogonalCut::feed_force, out.birge_feed, draws, rng);
  const Eigen::ArrayXXd ratio = draw_means(at, &OrthogonalCut::chip_ratio, 1.0, draws, rng);

  const Line cutting = line_fits(h.array(), fc), feed = line_fits(h.array(), ff);
  const Eigen::ArrayXd k_c = cutting.slope / setup.cut_width, k_f = feed.slope / setup.cut_width;  // Pa
  const double tan_gamma = std::tan(gamma);
  const Eigen::ArrayXd mu = (k_f + k_c * tan_gamma) / (k_c - k_f * tan_gamma);
  const Eigen::ArrayXd chip_ratio = ratio.rowwise().mean();
  const Eigen::ArrayXd phi = (std::cos(gamma) / (chip_ratio - std::sin(gamma))).atan();
  const Eigen::ArrayXd friction_angle = mu.atan();
  const Eigen::ArrayXd theta = friction_angle + phi - gamma;
  const Eigen::ArrayXd c_neq = (1.0 + std::numbers::pi / 2.0 - 2.0 * phi - theta.tan()).max(0.0);
  const Eigen::ArrayXd contact_per_h =
      theta.sin() / (friction_angle.cos() * phi.sin()) * (1.0 + c_neq / (3.0 * theta.tan()));
  const Eigen::ArrayXd pressure = (k_c * std::cos(gamma) - k_f * std::sin(gamma)) / contact_per_h;
  const double speed = out.cutting_speed;
  const Eigen::ArrayXd sliding_velocity = speed / chip_ratio;

  ThermalDraws thermal{Eigen::ArrayXd(draws), Eigen::ArrayXd(draws), Eigen::ArrayXd(draws)};
  const double log_low = std::log(setup.secondary_zone_ratio.low), log_high = std::log(setup.secondary_zone_ratio.high);
  for (int d = 0; d < draws; ++d) thermal.delta(d) = std::exp(rng.uniform(log_low, log_high));
  for (int d = 0; d < draws; ++d) thermal.conductivity(d) = rng.uniform(setup.conductivity.low, setup.conductivity.high);
  for (int d = 0; d < draws; ++d) thermal.specific_heat(d) = rng.uniform(setup.specific_heat.low, setup.specific_heat.high);
  Eigen::ArrayXXd temperatures(draws, n);
  for (Eigen::Index j = 0; j < n; ++j)
    temperatures.col(j) = oxley_interface_temperature(setup, speed, h(j), k_c, k_f, chip_ratio, phi, contact_per_h * h(j), thermal);

  const std::pair<const Eigen::ArrayXd*, const char*> checked[] = {
      {&mu, "friction coefficient"}, {&pressure, "normal stress"}, {&contact_per_h, "contact length"}, {nullptr, "temperature"}};
  for (const auto& [values, what] : checked) {
    if (!(values ? values->isFinite().all() : temperatures.isFinite().all())) {
      throw Error("orthogonal cuts at " + speed_words(speed) + " (" + at.front()->row_name + " ...): the forces give a " + what +
                  " that is not a finite number in some draws: the feed force's line is as steep as the rake angle allows, or "
                  "the chip ratio is at sin(rake)");
    }
  }
  // A draw in the tail of the measured scatter can give μ ≤ 0 (the feed force's line sloping down):
  // kept, as the analysis this replaces kept it, and counted for the summary.
  out.nonpositive_mu_draws = static_cast<int>((mu <= 0.0).count());
  out.mu = monte_carlo_estimate(mu);
  out.contact_pressure = monte_carlo_estimate(pressure);
  out.sliding_velocity = monte_carlo_estimate(sliding_velocity);
  out.temperature = monte_carlo_estimate(temperatures.rowwise().mean());
  out.temperature_thinnest = monte_carlo_estimate(temperatures.col(0));
  out.temperature_thickest = monte_carlo_estimate(temperatures.col(n - 1));
  out.chip_ratio = monte_carlo_estimate(chip_ratio);
  out.shear_angle = monte_carlo_estimate(phi);
  out.contact_length_per_h = monte_carlo_estimate(contact_per_h);
  out.oxley_c_neq = monte_carlo_estimate(c_neq);
  out.specific_cutting_force = monte_carlo_estimate(k_c);
  out.specific_feed_force = monte_carlo_estimate(k_f);
  out.edge_cutting_force = monte_carlo_estimate(cutting.intercept);
  out.edge_feed_force = monte_carlo_estimate(feed.intercept);
  return out;
}

void check_setup(const OrthogonalCutSetup& setup) {
  auto positive = [](double v, const char* field) {
    if (!(v > 0.0) || !std::isfinite(v)) throw Error(std::string("orthogonal-cut setup: ") + field + " must be positive");
  };
  positive(setup.cut_width, "cut_width");
  positive(setup.density, "density");
  positive(setup.room_temperature, "room_temperature");
  for (const auto& [range, field] : {std::pair{setup.conductivity, "conductivity"}, std::pair{setup.specific_heat, "specific_heat"},
                                     std::pair{setup.secondary_zone_ratio, "secondary_zone_ratio"}}) {
    positive(range.low, field);
    if (range.high < range.low) throw Error(std::string("orthogonal-cut setup: ") + field + "'s range has its high below its low");
  }
  if (!(std::abs(setup.rake_angle) < std::numbers::pi / 3.0))
    throw Error("orthogonal-cut setup: rake_angle must lie within ±60 deg");
  if (setup.draws < 2) throw Error("orthogonal-cut setup: draws must be at least 2");
}

}  // namespace

McEstimate monte_carlo_estimate(const Eigen::ArrayXd& draws) {
  const double mean = draws.mean();
  const double sd = draws.size() > 1 ? std::sqrt((draws - mean).square().sum() / static_cast<double>(draws.size() - 1)) : 0.0;
  return {mean, sd};
}

std::vector<RakeFaceEstimate> rake_face_from_orthogonal_cuts(const std::vector<OrthogonalCut>& cuts,
                                                             const OrthogonalCutSetup& setup) {
  check_setup(setup);
  std::map<double, std::map<double, std::vector<const OrthogonalCut*>>> grouped;
  for (const auto& cut : cuts) {
    for (const auto& [value, field] : {std::pair{cut.cutting_speed, "cutting speed"},
                                       std::pair{cut.uncut_chip_thickness, "uncut chip thickness"},
                                       std::pair{cut.chip_ratio.mean, "chip ratio"}}) {
      if (!(value > 0.0)) throw Error(cut.row_name + ": the " + field + " must be positive");
    }
    for (const auto& [m, field] : {std::pair{cut.cutting_force, "cutting force"}, std::pair{cut.feed_force, "feed force"},
                                   std::pair{cut.chip_ratio, "chip ratio"}}) {
      if (!(m.standard_error > 0.0))
        throw Error(cut.row_name + ": the " + std::string(field) +
                    "'s uncertainty must be positive (a mean without its scatter cannot weight the lines)");
    }
    grouped[cut.group][cut.cutting_speed].push_back(&cut);
  }
  NumpyRandom rng(setup.seed);
  std::vector<RakeFaceEstimate> out;
  for (auto& [group, speeds] : grouped) {
    for (auto& [speed, at] : speeds) {
      std::sort(at.begin(), at.end(), [](const auto* a, const auto* b) { return a->uncut_chip_thickness < b->uncut_chip_thickness; });
      for (size_t j = 1; j < at.size(); ++j) {
        if (at[j]->uncut_chip_thickness == at[j - 1]->uncut_chip_thickness)
          throw Error(at[j]->row_name + " and " + at[j - 1]->row_name + ": the same cutting speed and uncut chip thickness twice: give their mean");
      }
      if (at.size() < 2)
        throw Error(at.front()->row_name + ": the only uncut chip thickness at " + speed_words(speed) +
                    ": the edge's forces come apart only from a line through at least two thicknesses");
      out.push_back(analyse_speed(at, setup, rng));
    }
  }
  return out;
}

}  // namespace mufric
