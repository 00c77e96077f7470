#include "micro/contact/adhesion_table.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/units.hpp"

namespace mufric::contact {
namespace {

// Values closer than this (relative) are one grid value: a table written with rounded numbers.
constexpr double kSameGridValue = 1e-9;

// The distinct values of a column, increasing.
std::vector<double> grid_axis(const std::vector<double>& column) {
  std::vector<double> axis = column;
  std::sort(axis.begin(), axis.end());
  std::vector<double> distinct;
  for (const double x : axis) {
    if (distinct.empty() || std::abs(x - distinct.back()) > kSameGridValue * std::max(std::abs(x), 1.0)) distinct.push_back(x);
  }
  return distinct;
}

size_t index_on(const std::vector<double>& axis, double x) {
  const auto it = std::lower_bound(axis.begin(), axis.end(), x - kSameGridValue * std::max(std::abs(x), 1.0));
  return static_cast<size_t>(it - axis.begin());
}

// The cell of `axis` holding x and the weight of its upper end (held at the edges).
struct Bracket {
  size_t lo = 0, hi = 0;
  double weight = 0.0;      // of hi
  double inverse_width = 0.0;  // 1/(x_hi − x_lo) inside the grid, 0 at a held edge
};
Bracket bracket(const std::vector<double>& axis, double x) {
  if (axis.size() == 1 || x < axis.front()) return {0, 0, 0.0, 0.0};
  if (x > axis.back()) return {axis.size() - 1, axis.size() - 1, 0.0, 0.0};
  // On the grid's own edges the edge cell's slope holds (a pressure exactly on the table's first row).
  const auto hi = std::min(axis.size() - 1, static_cast<size_t>(std::upper_bound(axis.begin(), axis.end(), x) - axis.begin()));
  const double width = axis[hi] - axis[hi - 1];
  return {hi - 1, hi, (x - axis[hi - 1]) / width, 1.0 / width};
}

}  // namespace

AdhesionTable::AdhesionTable(std::vector<double> pressures, std::vector<double> velocities,
                             std::vector<double> temperatures, std::vector<double> mu, std::string source)
    : p_(std::move(pressures)), v_(std::move(velocities)), t_(std::move(temperatures)), mu_(std::move(mu)),
      source_(std::move(source)) {
  for (const auto* axis : {&p_, &v_, &t_}) {
    if (axis->empty()) throw Error("adhesion table " + source_ + ": an axis has no values");
    if (!std::is_sorted(axis->begin(), axis->end()) || std::adjacent_find(axis->begin(), axis->end()) != axis->end()) {
      throw Error("adhesion table " + source_ + ": axis values must increase strictly");
    }
  }
  if (mu_.size() != p_.size() * v_.size() * t_.size()) {
    throw Error("adhesion table " + source_ + ": " + std::to_string(mu_.size()) + " values for a grid of " +
                std::to_string(p_.size() * v_.size() * t_.size()));
  }
}

AdhesionTable AdhesionTable::read(const std::string& path) {
  const CsvTable table = read_csv_table(path);
  const std::vector<double> p = table.si_column(std::string(input_name::contact_pressure), QuantityKind::pressure);
  const std::vector<double> v = table.si_column(std::string(input_name::sliding_velocity), QuantityKind::velocity);
  const std::vector<double> t = table.si_column(std::string(input_name::temperature), QuantityKind::temperature);
  const std::vector<double> mu = table.si_column("mu_a");
  if (mu.empty()) throw Error(path + ": no rows");
  const std::vector<double> p_axis = grid_axis(p), v_axis = grid_axis(v), t_axis = grid_axis(t);
  const size_t nv = v_axis.size(), nt = t_axis.size();
  std::vector<double> values(p_axis.size() * nv * nt, std::nan(""));
  std::vector<int> line_of(values.size(), 0);
  for (size_t r = 0; r < mu.size(); ++r) {
    const std::string at = path + ": line " + std::to_string(table.line_of_row[r]) + ": ";
    if (!(mu[r] >= 0.0)) throw Error(at + "mu_a must be >= 0 (is " + std::to_string(mu[r]) + ")");
    if (!(p[r] >= 0.0) || !(v[r] >= 0.0) || !(t[r] > 0.0)) {
      throw Error(at + "contact_pressure and sliding_velocity must be >= 0, temperature above absolute zero");
    }
    const size_t cell = (index_on(p_axis, p[r]) * nv + index_on(v_axis, v[r])) * nt + index_on(t_axis, t[r]);
    if (line_of[cell] != 0) throw Error(at + "repeats the grid point of line " + std::to_string(line_of[cell]));
    values[cell] = mu[r];
    line_of[cell] = table.line_of_row[r];
  }
  for (size_t i = 0; i < p_axis.size(); ++i) {
    for (size_t j = 0; j < nv; ++j) {
      for (size_t k = 0; k < nt; ++k) {
        if (line_of[(i * nv + j) * nt + k] != 0) continue;
        throw Error(path + ": the grid has no row for contact_pressure " + format_human(p_axis[i], QuantityKind::pressure) +
                    ", sliding_velocity " + format_human(v_axis[j], QuantityKind::velocity) + ", temperature " +
                    format_human(t_axis[k], QuantityKind::temperature) +
                    " (a full grid is needed: every pressure with every velocity and temperature)");
      }
    }
  }
  return AdhesionTable(p_axis, v_axis, t_axis, values, path);
}

// Trilinear interpolation on the cell holding (p, v, T) (e.g. Press et al., Numerical Recipes, 3rd
// ed. 2007, §3.6), and its derivative in p for the contact's tangent.
AdhesionTable::Value AdhesionTable::at(double pressure_pa, double velocity_m_per_s, double temperature_k) const {
  const Bracket bp = bracket(p_, pressure_pa), bv = bracket(v_, velocity_m_per_s), bt = bracket(t_, temperature_k);
  const size_t nv = v_.size(), nt = t_.size();
  auto value = [&](size_t i, size_t j, size_t k) { return mu_[(i * nv + j) * nt + k]; };
  // μ on the p-faces of the cell, bilinear in (v, T).
  // (a + w (b − a): a table that is constant over a cell returns its value to the bit)
  auto lerp = [](double a, double b, double w) { return a + w * (b - a); };
  auto face = [&](size_t i) {
    const double low_v = lerp(value(i, bv.lo, bt.lo), value(i, bv.lo, bt.hi), bt.weight);
    const double high_v = lerp(value(i, bv.hi, bt.lo), value(i, bv.hi, bt.hi), bt.weight);
    return lerp(low_v, high_v, bv.weight);
  };
  const double lo = face(bp.lo), hi = face(bp.hi);
  return {lerp(lo, hi, bp.weight), (hi - lo) * bp.inverse_width};
}

std::string AdhesionTable::range() const {
  auto span = [](const std::vector<double>& axis, QuantityKind kind) {
    return axis.size() == 1 ? format_human(axis.front(), kind)
                            : format_human(axis.front(), kind) + " to " + format_human(axis.back(), kind);
  };
  return "p " + span(p_, QuantityKind::pressure) + ", v " + span(v_, QuantityKind::velocity) + ", T " +
         span(t_, QuantityKind::temperature);
}

}  // namespace mufric::contact
