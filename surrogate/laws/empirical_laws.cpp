#include "surrogate/laws/empirical_laws.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "common/csv_table.hpp"
#include "common/error.hpp"

namespace mufric {
namespace {

constexpr double kPascalPerMpa = 1e6;
constexpr double kMetrePerSecondPerMetrePerMinute = 1.0 / 60.0;
constexpr double kPeriodDeg = 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
// Measurements at angles closer than this are one group when fitting.
constexpr double kSameAngleDeg = 1e-9;
// Listing 1 of seed 001.
constexpr double kListing1MuMin = 0.093755565;
constexpr double kListing1MuMax = 0.322395506;

double wrap_degrees(double deg) {
  double wrapped = std::fmod(deg, kPeriodDeg);
  if (wrapped < 0.0) wrapped += kPeriodDeg;
  return wrapped;
}

std::vector<MlrRow> with_listing1_clamp(std::vector<MlrRow> rows) {
  for (auto& row : rows) {
    row.mu_min = kListing1MuMin;
    row.mu_max = kListing1MuMax;
  }
  return rows;
}

}  // namespace

CoulombLaw::CoulombLaw(double mu, InputSpace inputs) : FrictionModel(std::move(inputs)), mu_(mu) {
  if (!std::isfinite(mu) || mu < 0.0) throw Error("Coulomb law: mu must be finite and >= 0, got " + std::to_string(mu));
}

void CoulombLaw::evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  out.mu.setConstant(x.rows(), mu_);
  if (what.std || what.ci_level > 0.0) out.std.setZero(x.rows());
  if (what.gradient) out.gradient.setZero(x.rows(), x.cols());
}

std::string CoulombLaw::summary() const {
  return "Coulomb law, constant mu = " + std::to_string(mu_) + " (no uncertainty model: zero-width interval)";
}

MlrLaw::MlrLaw(std::vector<MlrRow> rows, std::string source, InputSpace inputs)
    : FrictionModel(std::move(inputs)), rows_(std::move(rows)), source_(std::move(source)) {
  if (rows_.empty()) throw Error("MLR law: no fibre angles");
  if (this->inputs().size() != 3 || this->inputs()[0].name != input_name::contact_pressure ||
      this->inputs()[1].name != input_name::sliding_velocity || this->inputs()[2].name != input_name::fibre_angle) {
    throw Error("MLR law: inputs must be contact_pressure, sliding_velocity, fibre_angle");
  }
  for (auto& row : rows_) {
    const std::string at = "MLR law, fibre angle " + std::to_string(row.fibre_angle_deg) + " deg: ";
    if (!std::isfinite(row.beta0) || !std::isfinite(row.beta1_per_m_min) || !std::isfinite(row.beta2_per_mpa)) {
      throw Error(at + "non-finite coefficient");
    }
    if (!(row.mu_min <= row.mu_max)) throw Error(at + "mu_min exceeds mu_max");
    row.fibre_angle_deg = wrap_degrees(row.fibre_angle_deg);
  }
  std::sort(rows_.begin(), rows_.end(), [](const MlrRow& a, const MlrRow& b) { return a.fibre_angle_deg < b.fibre_angle_deg; });
  for (size_t i = 1; i < rows_.size(); ++i) {
    if (rows_[i].fibre_angle_deg - rows_[i - 1].fibre_angle_deg < kSameAngleDeg) {
      throw Error("MLR law: fibre angle " + std::to_string(rows_[i].fibre_angle_deg) + " deg appears twice");
    }
  }
}

InputSpace MlrLaw::seed001_box() {
  return {{std::string(input_name::contact_pressure), "Pa", 0.0, 200e6},
          {std::string(input_name::sliding_velocity), "m/s", 1.0 / 60.0, 15.0 / 60.0},
          {std::string(input_name::fibre_angle), "rad", 0.0, std::numbers::pi}};
}

MlrLaw MlrLaw::seed001_table2() {
  return MlrLaw(with_listing1_clamp({
                    {0.0, 0.2803690, -0.0015720, -0.0012253, 0, 0, 0.93},
                    {22.5, 0.1644200, 0.0050902, -0.0006417, 0, 0, 0.837},
                    {45.0, 0.0974485, -0.0004083, 0.0001334, 0, 0, 0.905},
                    {67.5, 0.3047650, -0.0053778, -0.0006111, 0, 0, 0.905},
                    {90.0, 0.1211090, 0.0130631, -0.0003668, 0, 0, 0.738},
                    {112.5, 0.1763290, -0.0039313, 0.0008020, 0, 0, 0.679},
                    {135.0, 0.1679290, -0.0069309, 0.0006020, 0, 0, 0.837},
                    {157.5, 0.1060290, 0.0018082, 0.0007306, 0, 0, 0.949},
                }),
                "Seward et al. 2022, Table 2 (ACOF MLR), clamp of Listing 1", seed001_box());
}

MlrLaw MlrLaw::seed001_table4() {
  return MlrLaw(with_listing1_clamp({
                    {0.0, 0.052488, 0.006025, 0.0003908, 0, 0, 0.847},
                    {22.5, 0.197959, -0.001155, -0.000634, 0, 0, 0.793},
                    {45.0, 0.240492, -0.005277, -0.000341, 0, 0, 0.786},
                    {67.5, 0.18297, 0.007671, -0.000392, 0, 0, 0.466},
                    {90.0, 0.149911, 0.013133, -0.000753, 0, 0, 0.715},
                    {112.5, 0.081576, -0.001422, 0.0008751, 0, 0, 0.634},
                    {135.0, 0.156666, 0.014112, -0.000684, 0, 0, 0.689},
                    {157.5, 0.075583, 0.000894, 0.000419, 0, 0, 0.7111},
                }),
                "Seward et al. 2022, Table 4 (ADCOF MLR), clamp of Listing 1", seed001_box());
}

void MlrLaw::evaluate_valid(const QueryBatch& x, const EvaluationRequest& what, Evaluation& out) const {
  const Eigen::Index m = x.rows();
  out.mu.resize(m);
  if (what.std || what.ci_level > 0.0) out.std.setZero(m);
  if (what.gradient) out.gradient.setZero(m, 3);
  const size_t count = rows_.size();
  for (Eigen::Index i = 0; i < m; ++i) {
    const double p_mpa = x(i, 0) / kPascalPerMpa;
    const double v_m_min = x(i, 1) / kMetrePerSecondPerMetrePerMinute;
    const double theta = wrap_degrees(x(i, 2) * kRadToDeg);
    // Neighbouring tabulated angles a ≤ θ < b on the 180° circle.
    size_t upper = static_cast<size_t>(
        std::upper_bound(rows_.begin(), rows_.end(), theta,
                         [](double t, const MlrRow& r) { return t < r.fibre_angle_deg; }) -
        rows_.begin());
    const MlrRow& a = rows_[(upper + count - 1) % count];
    const MlrRow& b = rows_[upper % count];
    double span = b.fibre_angle_deg - a.fibre_angle_deg;
    double offset = theta - a.fibre_angle_deg;
    if (span <= 0.0) span += kPeriodDeg;
    if (offset < 0.0) offset += kPeriodDeg;
    const double weight_b = count == 1 ? 0.0 : offset / span;

    auto clamped = [&](const MlrRow& r, double& dmu_dp, double& dmu_dv) {
      const double raw = r.beta0 + r.beta1_per_m_min * v_m_min + r.beta2_per_mpa * p_mpa;
      const bool inside = raw > r.mu_min && raw < r.mu_max;
      dmu_dp = inside ? r.beta2_per_mpa / kPascalPerMpa : 0.0;
      dmu_dv = inside ? r.beta1_per_m_min / kMetrePerSecondPerMetrePerMinute : 0.0;
      return std::clamp(raw, r.mu_min, r.mu_max);
    };
    double dpa = 0, dva = 0, dpb = 0, dvb = 0;
    const double mu_a = clamped(a, dpa, dva);
    const double mu_b = clamped(b, dpb, dvb);
    out.mu(i) = (1.0 - weight_b) * mu_a + weight_b * mu_b;
    if (what.gradient) {
      out.gradient(i, 0) = (1.0 - weight_b) * dpa + weight_b * dpb;
      out.gradient(i, 1) = (1.0 - weight_b) * dva + weight_b * dvb;
      out.gradient(i, 2) = count == 1 ? 0.0 : (mu_b - mu_a) / span * kRadToDeg;
    }
  }
}

std::string MlrLaw::summary() const {
  std::ostringstream s;
  s << "empirical law mu = b0 + b1*v[m/min] + b2*p[MPa] per fibre angle, clamped (" << source_ << ")\n";
  s << "  angle[deg]        b0        b1        b2    mu_min    mu_max     R^2";
  for (const auto& r : rows_) {
    char line[160];
    std::snprintf(line, sizeof line, "\n  %10.3f %9.6f %9.6f %9.6f %9.6f %9.6f %7.3f", r.fibre_angle_deg, r.beta0,
                  r.beta1_per_m_min, r.beta2_per_mpa, r.mu_min, r.mu_max, r.r_squared);
    s << line;
  }
  return s.str();
}

MlrLaw fit_mlr_law(const std::string& csv_path, MlrFitReport* report) {
  const CsvTable table = read_csv_table(csv_path);
  const auto angle = table.si_column(std::string(input_name::fibre_angle));
  const auto pressure = table.si_column(std::string(input_name::contact_pressure));
  const auto velocity = table.si_column(std::string(input_name::sliding_velocity));
  const auto mu = table.si_column("mu");
  std::map<long long, std::vector<size_t>> groups;  // angle in 1e-9 deg steps → rows
  for (size_t i = 0; i < angle.size(); ++i) {
    groups[std::llround(wrap_degrees(angle[i] * kRadToDeg) / kSameAngleDeg)].push_back(i);
  }
  if (groups.empty()) throw Error(csv_path + ": no measurements");
  std::vector<MlrRow> rows;
  MlrFitReport fit;
  for (const auto& [key, members] : groups) {
    const double angle_deg = static_cast<double>(key) * kSameAngleDeg;
    const auto k = static_cast<Eigen::Index>(members.size());
    const std::string at = csv_path + ": fibre angle " + std::to_string(angle_deg) + " deg: ";
    if (k < 3) throw Error(at + std::to_string(k) + " measurements; at least 3 are needed for b0, b1, b2");
    Eigen::MatrixXd design(k, 3);
    Eigen::VectorXd target(k);
    for (Eigen::Index r = 0; r < k; ++r) {
      const size_t row = members[static_cast<size_t>(r)];
      design(r, 0) = 1.0;
      design(r, 1) = velocity[row] / kMetrePerSecondPerMetrePerMinute;
      design(r, 2) = pressure[row] / kPascalPerMpa;
      target(r) = mu[row];
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(design);
    if (qr.rank() < 3) {
      throw Error(at + "velocity and pressure do not vary independently; b1 and b2 cannot both be fitted");
    }
    const Eigen::Vector3d beta = qr.solve(target);
    const double ss_res = (design * beta - target).squaredNorm();
    const double ss_tot = (target.array() - target.mean()).square().sum();
    const double r2 = ss_tot > 0.0 ? 1.0 - ss_res / ss_tot : 1.0;
    rows.push_back({angle_deg, beta(0), beta(1), beta(2), target.minCoeff(), target.maxCoeff(), r2});
    fit.angles.push_back({angle_deg, static_cast<long long>(k), r2});
  }
  // The box of the measurements, angles over the full half-turn the interpolation covers.
  InputSpace box = MlrLaw::seed001_box();
  box[0].lo = *std::min_element(pressure.begin(), pressure.end());
  box[0].hi = *std::max_element(pressure.begin(), pressure.end());
  box[1].lo = *std::min_element(velocity.begin(), velocity.end());
  box[1].hi = *std::max_element(velocity.begin(), velocity.end());
  for (size_t j = 0; j < 2; ++j) {
    if (!(box[j].lo < box[j].hi)) throw Error(csv_path + ": " + box[j].name + " does not vary; the law cannot be fitted");
  }
  if (report) *report = fit;
  return MlrLaw(std::move(rows), "fitted to " + csv_path, std::move(box));
}

// ---- the model file (/coulomb, /mlr) ---------------------------------------------------------

namespace {
std::vector<double> column(const std::vector<MlrRow>& rows, double MlrRow::*field) {
  std::vector<double> values;
  for (const auto& r : rows) values.push_back(r.*field);
  return values;
}
}  // namespace

void CoulombLaw::write(h5::Writer& out) const {
  out.group("/coulomb");
  out.double_attribute("/coulomb", "mu", mu_);
}

CoulombLaw CoulombLaw::read(const h5::Reader& in, InputSpace inputs) {
  return CoulombLaw(in.double_attribute("/coulomb", "mu"), std::move(inputs));
}

// ---- MLR -----------------------------------------------------------------------------------
void MlrLaw::write(h5::Writer& out) const {
  out.group("/mlr");
  out.string_attribute("/mlr", "source", source_);
  out.string_attribute("/mlr", "units", "mu = beta0 + beta1*v[m/min] + beta2*p[MPa]; angles in degrees");
  out.doubles("/mlr/fibre_angle_deg", column(rows_, &MlrRow::fibre_angle_deg));
  out.doubles("/mlr/beta0", column(rows_, &MlrRow::beta0));
  out.doubles("/mlr/beta1_per_m_min", column(rows_, &MlrRow::beta1_per_m_min));
  out.doubles("/mlr/beta2_per_mpa", column(rows_, &MlrRow::beta2_per_mpa));
  out.doubles("/mlr/mu_min", column(rows_, &MlrRow::mu_min));
  out.doubles("/mlr/mu_max", column(rows_, &MlrRow::mu_max));
  out.doubles("/mlr/r_squared", column(rows_, &MlrRow::r_squared));
}

MlrLaw MlrLaw::read(const h5::Reader& in, InputSpace inputs) {
  const auto angles = in.doubles("/mlr/fibre_angle_deg");
  const auto k = static_cast<Eigen::Index>(angles.size());
  const Eigen::VectorXd b0 = in.vector("/mlr/beta0", k), b1 = in.vector("/mlr/beta1_per_m_min", k),
                        b2 = in.vector("/mlr/beta2_per_mpa", k), lo = in.vector("/mlr/mu_min", k),
                        hi = in.vector("/mlr/mu_max", k), r2 = in.vector("/mlr/r_squared", k);
  std::vector<MlrRow> rows;
  for (Eigen::Index i = 0; i < k; ++i) {
    rows.push_back({angles[static_cast<size_t>(i)], b0(i), b1(i), b2(i), lo(i), hi(i), r2(i)});
  }
  return MlrLaw(std::move(rows), in.string_attribute("/mlr", "source"), std::move(inputs));
}


}  // namespace mufric
