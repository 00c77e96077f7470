#include "micro/coupling/chip_interface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/error.hpp"

namespace mufric::coupling {

PeriodicGraph::PeriodicGraph(std::function<Eigen::Vector2d(double)> point, double lo, double period, int samples)
    : point_(std::move(point)), lo_(lo), period_(period) {
  if (!(period_ > 0.0) || samples < 4) throw Error("periodic graph: needs a positive period and at least 4 samples");
  for (int k = 0; k <= samples; ++k) {
    const double t = lo_ + period_ * k / samples;
    t_.push_back(t);
    const Eigen::Vector2d at = point_(t);
    x_.push_back(at.x());
    y_.push_back(at.y());
  }
  interval_ = x_.back() - x_.front();
  if (!(interval_ > 0.0)) throw Error("periodic graph: the curve does not advance in x over a period");
  for (size_t k = 1; k < x_.size(); ++k) folded_ = folded_ || !(x_[k] > x_[k - 1]);
}

double PeriodicGraph::root_in(size_t j, double xr) const {
  double a = t_[j], b = t_[j + 1];
  double fa = x_[j] - xr, fb = x_[j + 1] - xr;
  const double tolerance = kGraphParameterTolerance * period_;
  // Illinois: regula falsi that halves the retained end's value when the same end stays twice.
  int side = 0;
  double t = a;
  for (int k = 0; k < 100 && std::abs(b - a) > tolerance; ++k) {
    if (fa == 0.0) return a;
    if (fb == 0.0) return b;
    t = (a * fb - b * fa) / (fb - fa);
    if (!(t > std::min(a, b) && t < std::max(a, b))) t = 0.5 * (a + b);
    const double ft = point_(t).x() - xr;
    if (std::abs(ft) <= kGraphParameterTolerance * interval_) break;
    if ((ft < 0.0) == (fa < 0.0)) {
      a = t, fa = ft;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = t, fb = ft;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return t;
}

double PeriodicGraph::parameter_at(double x) const {
  const double periods = std::floor((x - x_.front()) / interval_);
  const double xr = x - periods * interval_;
  if (!folded_) {
    auto it = std::upper_bound(x_.begin(), x_.end(), xr);
    const auto j = static_cast<size_t>(std::clamp<std::ptrdiff_t>(it - x_.begin() - 1, 0, static_cast<std::ptrdiff_t>(x_.size()) - 2));
    return root_in(j, xr) + periods * period_;
  }
  // Every sample interval whose ends straddle xr holds a root; the highest point wins.
  double best_t = 0.0, best_y = -std::numeric_limits<double>::infinity();
  for (size_t j = 0; j + 1 < x_.size(); ++j) {
    if ((x_[j] - xr) * (x_[j + 1] - xr) > 0.0) continue;
    const double t = root_in(j, xr);
    const double y = point_(t).y();
    if (y > best_y) best_y = y, best_t = t;
  }
  return best_t + periods * period_;
}

double PeriodicGraph::ramped_height_at(double x, double max_slope) const {
  const double xr = x - std::floor((x - x_.front()) / interval_) * interval_;
  double height = height_at(x);
  for (size_t k = 0; k + 1 < x_.size(); ++k) {  // the last sample is the first's periodic image
    for (const double image : {-interval_, 0.0, interval_}) {
      height = std::max(height, y_[k] - max_slope * std::abs(xr - (x_[k] + image)));
    }
  }
  return height;
}

ChipSurface::ChipSurface(const solid::IgaSpace& chip)
    : chip_(chip),
      u_(Eigen::VectorXd::Zero(chip.dof_count())),
      v_(Eigen::VectorXd::Zero(chip.dof_count())),
      graph_([this](double t) { return position(t); }, chip.patch().u_basis().lo(), chip.patch().u_basis().period(),
             8 * chip.patch().u_basis().count()) {
  if (!chip_.patch().u_basis().is_periodic()) throw Error("chip surface: the chip patch must be periodic along x");
}

void ChipSurface::update(const Eigen::VectorXd& u, const Eigen::VectorXd& v) {
  if (u.size() != chip_.dof_count() || v.size() != chip_.dof_count()) throw Error("chip surface: wrong field size");
  u_ = u;
  v_ = v;
  const auto& b = chip_.patch().u_basis();
  graph_ = PeriodicGraph([this](double t) { return position(t); }, b.lo(), b.period(), 8 * b.count());
}

Eigen::Vector2d ChipSurface::position(double t) const {
  const double top = chip_.patch().v_basis().hi();
  return chip_.patch().point(t, top) + chip_.displacement(u_, t, top);
}

Eigen::Vector2d ChipSurface::velocity(double t) const { return chip_.displacement(v_, t, chip_.patch().v_basis().hi()); }

Eigen::VectorXd ChipSurface::nodal_forces(const std::vector<Eigen::Vector2d>& positions,
                                          const std::vector<Eigen::Vector2d>& tractions,
                                          const std::vector<double>& weights) const {
  if (positions.size() != tractions.size() || positions.size() != weights.size()) {
    throw Error("chip surface: positions, tractions and weights differ in number");
  }
  Eigen::VectorXd forces = Eigen::VectorXd::Zero(chip_.dof_count());
  const double top = chip_.patch().v_basis().hi();
  for (size_t q = 0; q < positions.size(); ++q) {
    const spline::RationalBasis b = chip_.patch().basis_at(parameter_at(positions[q].x()), top);
    for (size_t a = 0; a < b.nodes.size(); ++a) {
      forces.segment<2>(2 * b.nodes[a]) += b.r(static_cast<Eigen::Index>(a)) * weights[q] * tractions[q];
    }
  }
  return forces;
}

void NodalLoad::set(const Eigen::VectorXd& forces) {
  if (forces.size() != forces_.size()) throw Error("nodal load: wrong size");
  forces_ = forces;
}

bool NodalLoad::add(const Eigen::VectorXd&, Eigen::VectorXd& force, solid::TangentAccumulator*, std::string&) const {
  force -= forces_;  // an applied load enters the residual f_int + f − f_ext as f = −F
  return true;
}

namespace {

// The column positions (unreduced Greville abscissae) of a periodic basis and its collocation there.
struct Columns {
  std::vector<double> x;
  Eigen::PartialPivLU<Eigen::MatrixXd> collocation;
};

Columns columns_of(const spline::SplineBasis& basis) {
  const int n = basis.count();
  Columns c;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    c.x.push_back(basis.greville_abscissa(i));
    const auto loc = basis.locate(c.x.back());
    const Eigen::VectorXd values = basis.values(loc.span, loc.u);
    for (int j = 0; j <= basis.degree(); ++j) a(i, basis.function_index(loc.span, j)) += values(j);
  }
  c.collocation = a.partialPivLu();
  return c;
}

// Bottom and top control heights over the columns: the chip's and the tool's heights interpolated,
// the top raised where needed so that every top control point is min_film above its bottom one
// (the film, a combination of those differences with non-negative weights, is then ≥ min_film).
std::pair<Eigen::VectorXd, Eigen::VectorXd> boundary_heights(const Columns& c, const PeriodicGraph& chip,
                                                             const PeriodicGraph& tool, double min_film) {
  const auto n = static_cast<Eigen::Index>(c.x.size());
  Eigen::VectorXd chip_h(n), tool_h(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    chip_h(i) = chip.ramped_height_at(c.x[static_cast<size_t>(i)], kFilmFloorMaxSlope);
    tool_h(i) = tool.height_at(c.x[static_cast<size_t>(i)]);
  }
  const Eigen::VectorXd bottom = c.collocation.solve(chip_h);
  const Eigen::VectorXd tool_interpolant = c.collocation.solve(tool_h);
  const Eigen::VectorXd top = tool_interpolant.array().max(bottom.array() + min_film).matrix();
  return {bottom, top};
}

// The control net between a bottom and a top row of the same columns (row i + nu j): each column's
// points at the v basis' Greville fractions across the film, 0 at the chip and 1 at the tool.
Eigen::MatrixX2d net_between(const spline::SplineBasis& across, const Eigen::MatrixX2d& rows) {
  const auto nu = rows.rows() / 2;
  const int nv = across.count();
  Eigen::MatrixX2d points(nu * nv, 2);
  for (int j = 0; j < nv; ++j) {
    const double s = across.greville_abscissa(j);
    for (Eigen::Index i = 0; i < nu; ++i) {
      points.row(i + nu * j) = Eigen::RowVector2d(rows(i, 0), rows(i, 1) + s * (rows(nu + i, 1) - rows(i, 1)));
    }
  }
  return points;
}

}  // namespace

spline::SplineSurface gap_patch(const PeriodicGraph& chip, const PeriodicGraph& tool, double x0, const GapMeshOptions& o) {
  if (o.degree < 1 || o.elements_x < 2 || o.elements_y < 1 || !(o.min_film > 0.0)) {
    throw Error("gap mesh: needs degree >= 1, elements_x >= 2, elements_y >= 1 and a positive min_film");
  }
  if (std::abs(chip.interval() - tool.interval()) > 1e-9 * chip.interval()) {
    throw Error("gap mesh: the chip and the tool repeat over different intervals");
  }
  const spline::SplineBasis bu = spline::SplineBasis::periodic_uniform(o.degree, o.elements_x, x0, x0 + chip.interval());
  const spline::SplineBasis bv = spline::SplineBasis::open_uniform(o.degree, o.elements_y, 0.0, 1.0);
  const Columns c = columns_of(bu);
  const auto [bottom, top] = boundary_heights(c, chip, tool, o.min_film);
  const int nu = bu.count();
  Eigen::MatrixX2d rows(2 * nu, 2);
  for (int i = 0; i < nu; ++i) {
    rows.row(i) = Eigen::RowVector2d(c.x[static_cast<size_t>(i)], bottom(i));
    rows.row(nu + i) = Eigen::RowVector2d(c.x[static_cast<size_t>(i)], top(i));
  }
  spline::Points2 points = net_between(bv, rows);
  return spline::SplineSurface(bu, bv, std::move(points), {}, Eigen::Vector2d(chip.interval(), 0.0));
}

Eigen::MatrixX2d gap_net(const spline::SplineSurface& patch, const Eigen::MatrixX2d& rows) {
  if (rows.rows() != 2 * patch.u_basis().count()) throw Error("gap mesh: the rows do not match the patch's columns");
  return net_between(patch.v_basis(), rows);
}

Eigen::MatrixX2d gap_boundary_rows(const spline::SplineSurface& patch, const PeriodicGraph& chip, const PeriodicGraph& tool,
                                   const GapMeshOptions& o) {
  const Columns c = columns_of(patch.u_basis());
  const auto [bottom, top] = boundary_heights(c, chip, tool, o.min_film);
  const auto n = static_cast<Eigen::Index>(c.x.size());
  Eigen::MatrixX2d rows(2 * n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    rows.row(i) = Eigen::RowVector2d(c.x[static_cast<size_t>(i)], bottom(i));
    rows.row(n + i) = Eigen::RowVector2d(c.x[static_cast<size_t>(i)], top(i));
  }
  return rows;
}

}  // namespace mufric::coupling
