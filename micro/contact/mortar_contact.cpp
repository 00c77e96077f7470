#include "micro/contact/mortar_contact.hpp"

#include <algorithm>
#include <unordered_map>

#include "common/error.hpp"
#include "micro/contact/interface_laws.hpp"

namespace mufric::contact {

double RigidTool::lowest_y() const { return surface.points().col(1).minCoeff(); }

MortarContact::MortarContact(const solid::IgaSpace& space, RigidTool tool, double penalty, int points_per_span,
                             ContactInterface contact_interface)
    : tool_(std::move(tool)), interface_(std::move(contact_interface)), penalty_(penalty) {
  if (!(penalty_ > 0.0)) throw Error("contact: the penalty factor must be positive");
  if (!interface_.law) interface_.law = std::make_shared<FrictionlessLaw>();
  if (interface_.tangential_penalty == 0.0) interface_.tangential_penalty = kTangentialPenaltyRatio * penalty_;
  if (!(interface_.tangential_penalty > 0.0)) throw Error("contact: the tangential penalty must be positive");
  if (!kHeatPartitionRange.contains(interface_.heat_partition)) {
    throw Error("contact: the heat partition must be in [0, 1]");
  }
  seeds_ = std::make_shared<const spline::ProjectionSeeds>(tool_.surface);
  // A periodic tool profile that is a graph over x lets every search be bounded (see search_window).
  const auto& basis = tool_.surface.basis();
  if (basis.is_periodic() && tool_.surface.shift().y() == 0.0 && tool_.surface.shift().x() > 0.0) {
    constexpr int kSamplesPerSpan = 16;
    const int samples = kSamplesPerSpan * basis.count();
    for (int k = 0; k <= samples; ++k) {
      const double u = basis.lo() + basis.period() * k / samples;
      const Eigen::Vector2d p = tool_.surface.point(u);
      if (!graph_.empty() && !(p.x() > graph_.back().x)) {
        graph_.clear();  // not a graph: fall back to the global search
        break;
      }
      graph_.push_back({p.x(), p.y(), u});
    }
  }
  surface_nodes_ = space.side_nodes(numerics::Side::top);
  std::unordered_map<int, int> surface_index;
  for (size_t a = 0; a < surface_nodes_.size(); ++a) surface_index[surface_nodes_[a]] = static_cast<int>(a);
  node_area_.assign(surface_nodes_.size(), 0.0);
  node_points_.resize(surface_nodes_.size());
  const int per_span = points_per_span > 0 ? points_per_span : space.patch().u_basis().degree() + 3;
  for (const auto& bp : space.boundary(numerics::Side::top, per_span)) {
    SurfacePoint sp;
    sp.weight = bp.weight;
    sp.position = bp.position;
    std::vector<double> values;
    for (size_t k = 0; k < bp.nodes.size(); ++k) {
      const double r = bp.values(static_cast<Eigen::Index>(k));
      if (r == 0.0) continue;  // functions of the rows below the surface vanish there
      const auto it = surface_index.find(bp.nodes[k]);
      if (it == surface_index.end()) throw Error("contact: a non-surface function is non-zero on the top side");
      sp.nodes.push_back(bp.nodes[k]);
      sp.multipliers.push_back(it->second);
      values.push_back(r);
    }
    sp.values = Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
    const auto q = static_cast<int>(points_.size());
    for (size_t k = 0; k < sp.nodes.size(); ++k) {
      node_area_[static_cast<size_t>(sp.multipliers[k])] += sp.values(static_cast<Eigen::Index>(k)) * sp.weight;
      node_points_[static_cast<size_t>(sp.multipliers[k])].push_back({q, static_cast<int>(k)});
    }
    surface_length_ += sp.weight;
    points_.push_back(std::move(sp));
  }
  anchor_.assign(points_.size(), std::nullopt);
  step_dissipation_.assign(points_.size(), 0.0);
}

spline::ProjectionOptions MortarContact::search_window(const Eigen::Vector2d& x) const {
  spline::ProjectionOptions options;
  options.seeds = seeds_.get();  // refers to tool_.surface: a copy of this object searches without it
  if (graph_.empty()) return options;
  const double length = tool_.surface.shift().x(), period = tool_.surface.basis().period();
  // Tool height and parameter at an x anywhere, through the periodic table.
  auto at = [&](double xq) {
    const double turns = std::floor((xq - graph_.front().x) / length);
    const double xr = xq - turns * length;
    auto it = std::upper_bound(graph_.begin(), graph_.end(), xr, [](double v, const GraphSample& g) { return v < g.x; });
    if (it == graph_.begin()) it = graph_.begin() + 1;
    if (it == graph_.end()) it = graph_.end() - 1;
    const GraphSample& a = *(it - 1);
    const GraphSample& b = *it;
    const double t = (xr - a.x) / (b.x - a.x);
    return std::make_pair(a.y + t * (b.y - a.y), a.u + t * (b.u - a.u) + turns * period);
  };
  // The curve point straight above or below x is at most the vertical distance away, so the
  // closest point lies within that distance in x.
  const double reach = std::abs(x.y() - at(x.x()).first) + 2.0 * (graph_[1].x - graph_[0].x);
  const double du = graph_[1].u - graph_[0].u;
  options.window_lo = at(x.x() - reach).second - du;
  options.window_hi = at(x.x() + reach).second + du;
  return options;
}

std::vector<std::vector<int>> MortarContact::coupled_nodes() const {
  std::vector<std::vector<int>> groups;
  for (const auto& support : node_points_) {
    std::vector<int> group;
    for (const auto& [q, local] : support) {
      const auto& nodes = points_[static_cast<size_t>(q)].nodes;
      group.insert(group.end(), nodes.begin(), nodes.end());
    }
    std::sort(group.begin(), group.end());
    group.erase(std::unique(group.begin(), group.end()), group.end());
    groups.push_back(std::move(group));
  }
  return groups;
}

std::vector<MortarContact::PointGap> MortarContact::gaps(const Eigen::VectorXd& u, int& projections,
                                                         std::string& reason, bool& ok,
                                                         std::vector<Eigen::Vector2d>* positions) const {
  const size_t n = points_.size();
  std::vector<Eigen::Vector2d> x(n);
  std::vector<bool> near(n, false);
  const double lowest = tool_.lowest_y();
  for (size_t q = 0; q < n; ++q) {
    const auto& sp = points_[q];
    x[q] = sp.position;
    for (size_t k = 0; k < sp.nodes.size(); ++k) x[q] += sp.values(static_cast<Eigen::Index>(k)) * u.segment<2>(2 * sp.nodes[k]);
    near[q] = x[q].y() >= lowest;  // below the tool's lowest point a point cannot penetrate it
  }
  // Points in the support of a surface node that has a point near the tool are evaluated: the
  // weighted gap of such a node needs all of them. The rest of the surface is never searched.
  std::vector<bool> needed(n, false);
  for (const auto& support : node_points_) {
    const auto is_near = [&](const SupportPoint& s) { return near[static_cast<size_t>(s.point)]; };
    if (std::none_of(support.begin(), support.end(), is_near)) continue;
    for (const auto& s : support) needed[static_cast<size_t>(s.point)] = true;
  }
  std::vector<PointGap> out(n);
  projections = 0;
  for (size_t q = 0; q < n && ok; ++q) {
    if (!needed[q]) continue;
    const spline::Projection p = spline::project(tool_.surface, x[q], search_window(x[q]));
    ++projections;
    if (!p.converged) {
      ok = false;
      reason = "contact: closest-point projection failed at x = (" + std::to_string(x[q].x()) + ", " +
               std::to_string(x[q].y()) + "): " + p.reason;
      break;
    }
    const spline::CurveDerivatives d = tool_.surface.derivatives(p.u, 2);
    const Eigen::Vector2d t = d.row(1).transpose(), c2 = d.row(2).transpose();
    const double speed2 = t.squaredNorm();
    PointGap& g = out[q];
    g.evaluated = true;
    g.normal = Eigen::Vector2d(t.y(), -t.x()) / std::sqrt(speed2);
    g.gap = (p.foot - x[q]).dot(g.normal);
    // ∂²g/∂x² = −∂n/∂x = (n·C'')/(|C'|²(|C'|² − d n·C'')) C'⊗C', d = −g the signed distance.
    const double nc = g.normal.dot(c2);
    const double denominator = speed2 * (speed2 + g.gap * nc);
    g.hessian = denominator != 0.0 ? Eigen::Matrix2d(nc / denominator * t * t.transpose()) : Eigen::Matrix2d::Zero();
    g.parameter = p.u;
    g.d1 = t;
    g.d2 = c2;
    // From the foot's condition (x − C(ξ))·C′(ξ) = 0: ∂ξ/∂x = C′ / (|C′|² + g n·C″).
    if (speed2 + g.gap * nc != 0.0) g.parameter_gradient = t / (speed2 + g.gap * nc);
  }
  if (positions != nullptr) *positions = std::move(x);
  return out;
}

Eigen::VectorXd MortarContact::node_pressures(const std::vector<PointGap>& g) const {
  Eigen::VectorXd pressure = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(surface_nodes_.size()));
  for (size_t a = 0; a < surface_nodes_.size(); ++a) {
    double weighted = 0.0;
    bool complete = true;
    for (const auto& [q, local] : node_points_[a]) {
      const auto& sp = points_[static_cast<size_t>(q)];
      if (!g[static_cast<size_t>(q)].evaluated) {
        complete = false;
        break;
      }
      weighted += sp.values(local) * sp.weight * g[static_cast<size_t>(q)].gap;
    }
    if (complete && weighted > 0.0) pressure(static_cast<Eigen::Index>(a)) = penalty_ * weighted / node_area_[a];
  }
  return pressure;
}

double MortarContact::point_pressure(size_t q, const Eigen::VectorXd& node_pressure) const {
  const auto& sp = points_[q];
  double pq = 0.0;
  for (size_t k = 0; k < sp.nodes.size(); ++k) {
    pq += node_pressure(sp.multipliers[k]) * sp.values(static_cast<Eigen::Index>(k));
  }
  return pq;
}

Eigen::Matrix2d MortarContact::unit_tangent_gradient(const PointGap& g) {
  // t = C′/|C′|: ∂t/∂ξ = (C″ − t (t·C″))/|C′|, times ∂ξ/∂x.
  const double speed = g.d1.norm();
  const Eigen::Vector2d t = g.d1 / speed;
  const Eigen::Vector2d dt_dxi = (g.d2 - t * t.dot(g.d2)) / speed;
  return dt_dxi * g.parameter_gradient.transpose();
}

std::optional<std::string> MortarContact::missing_point_state() const {
  const PointStateNeeds needs = interface_.law->needs();
  if (!needs.any()) return std::nullopt;
  const std::optional<std::string> missing =
      states_ ? states_->missing(needs) : std::optional<std::string>("a provider of the contact points' state (set_point_states)");
  if (!missing) return std::nullopt;
  return "contact: the interfacial law " + std::string(interface_.law->name()) + " needs " + *missing;
}

MortarContact::PointShear MortarContact::point_shear(size_t q, const PointGap& g, double pressure) const {
  PointShear s;
  if (!interface_.law->frictional() || pressure <= 0.0 || !g.evaluated) return s;
  if (const auto missing = missing_point_state()) throw Error(*missing);
  // A point without an anchor (not searched at the last commit) starts stress-free where it is.
  if (!anchor_[q]) return s;
  // Tangential offset from the anchor along the tool, g_t = |C′(ξ)| (ξ − ξ_a): the arc length to
  // first order in ξ − ξ_a, which in stick stays of the order of τ/ε_t (sub-nanometre).
  const double speed = g.d1.norm();
  const double offset_parameter = g.parameter - *anchor_[q];
  const double offset = speed * offset_parameter;
  const double trial = -interface_.tangential_penalty * offset;
  s.trial = trial;
  // The law's slip limit at this point's state (its k, T and wetted flag as of the last accepted step).
  ContactPointState point = states_ ? states_->state(q) : ContactPointState{};
  point.pressure = pressure;
  const SlipLimit slip = interface_.law->slip_limit(point);
  const double limit = slip.shear;
  if (std::abs(trial) <= limit) {
    s.regime = PointShear::Regime::stick;
    s.shear = trial;
    // ∂g_t/∂x = (|C′| + (ξ − ξ_a) t·C″) ∂ξ/∂x.
    const double doffset_dxi = speed + offset_parameter * g.d2.dot(g.d1) / speed;
    s.shear_gradient = -interface_.tangential_penalty * doffset_dxi * g.parameter_gradient;
  } else {
    s.regime = PointShear::Regime::slip;
    s.slip_sign = trial > 0.0 ? 1.0 : -1.0;
    s.shear = s.slip_sign * limit;
    s.limit_slope = slip.dshear_dpressure;
  }
  return s;
}

std::vector<Eigen::Vector2d> MortarContact::surface_positions() const {
  std::vector<Eigen::Vector2d> x;
  x.reserve(points_.size());
  for (const auto& sp : points_) x.push_back(sp.position);
  return x;
}

void MortarContact::commit(const Eigen::VectorXd& u) {
  if (!interface_.law->frictional()) return;
  bool ok = true;
  int projections = 0;
  std::string reason;
  const std::vector<PointGap> g = gaps(u, projections, reason, ok, &committed_positions_);
  if (!ok) throw Error("contact: committing the accepted state: " + reason);
  const Eigen::VectorXd p = node_pressures(g);
  std::fill(step_dissipation_.begin(), step_dissipation_.end(), 0.0);
  step_dissipated_energy_ = 0.0;
  for (size_t q = 0; q < points_.size(); ++q) {
    if (!g[q].evaluated) {
      anchor_[q].reset();
      continue;
    }
    const PointShear s = point_shear(q, g[q], point_pressure(q, p));
    if (s.regime == PointShear::Regime::stick) continue;  // the anchor holds
    if (s.regime == PointShear::Regime::slip) {
      // Return map: the anchor follows so that −ε_t g_t is the slip shear. The slip it makes,
      // (|τ_trial| − |τ|)/ε_t, against the shear |τ| is the energy the point dissipates.
      step_dissipation_[q] = points_[q].weight * std::abs(s.shear) * (std::abs(s.trial) - std::abs(s.shear)) /
                             interface_.tangential_penalty;
      step_dissipated_energy_ += step_dissipation_[q];
      anchor_[q] = g[q].parameter + s.shear / (interface_.tangential_penalty * g[q].d1.norm());
    } else {
      anchor_[q] = g[q].parameter;  // out of contact (or just touching): stress-free where it is
    }
  }
  dissipated_energy_ += step_dissipated_energy_;
}

Eigen::VectorXd MortarContact::frictional_heat(Eigen::Index node_count) const {
  Eigen::VectorXd heat = Eigen::VectorXd::Zero(node_count);
  for (size_t q = 0; q < points_.size(); ++q) {
    if (step_dissipation_[q] == 0.0) continue;
    const auto& sp = points_[q];
    for (size_t k = 0; k < sp.nodes.size(); ++k) {
      heat(sp.nodes[k]) += interface_.heat_partition * step_dissipation_[q] * sp.values(static_cast<Eigen::Index>(k));
    }
  }
  return heat;
}

bool MortarContact::add(const Eigen::VectorXd& u, Eigen::VectorXd& force, solid::TangentAccumulator* tangent,
                        std::string& reason) const {
  if (interface_.law->frictional()) {
    if (const auto missing = missing_point_state()) {
      reason = *missing;
      return false;
    }
  }
  bool ok = true;
  int projections = 0;
  const std::vector<PointGap> g = gaps(u, projections, reason, ok);
  if (!ok) return false;
  const Eigen::VectorXd p = node_pressures(g);
  // G_a = ∂g_a/∂u = (1/A_a) Σ_q N_a(q) w_q (−R_b n_q) of every active node, as (node, ∂g_a/∂u_node)
  // over the few (p + 2) nodes of its support: a linear search in a small vector, not a hash map.
  std::vector<std::vector<std::pair<int, Eigen::Vector2d>>> gradients;
  if (tangent != nullptr) {
    gradients.resize(surface_nodes_.size());
    for (size_t a = 0; a < surface_nodes_.size(); ++a) {
      if (p(static_cast<Eigen::Index>(a)) <= 0.0) continue;
      auto& gradient = gradients[a];
      for (const auto& [q, local] : node_points_[a]) {
        const auto& sp = points_[static_cast<size_t>(q)];
        const double factor = sp.values(local) * sp.weight / node_area_[a];
        for (size_t b = 0; b < sp.nodes.size(); ++b) {
          auto it = std::find_if(gradient.begin(), gradient.end(), [&](const auto& e) { return e.first == sp.nodes[b]; });
          if (it == gradient.end()) it = gradient.insert(gradient.end(), {sp.nodes[b], Eigen::Vector2d::Zero()});
          it->second -= factor * sp.values(static_cast<Eigen::Index>(b)) * g[static_cast<size_t>(q)].normal;
        }
      }
    }
  }
  auto add_block = [&](int b, int c, const Eigen::Matrix2d& k) {
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) tangent->add(2 * b + i, 2 * c + j, k(i, j));
    }
  };
  // Mortar pressure at each point, P_q = Σ_a p_a N_a(q), and the law's shear τ_q along the tool's
  // unit tangent t_q: force f_b = −Σ_q w_q R_b (P_q n_q + τ_q t_q).
  for (size_t q = 0; q < points_.size(); ++q) {
    const auto& sp = points_[q];
    const double pq = point_pressure(q, p);
    if (pq <= 0.0) continue;
    const PointShear shear = point_shear(q, g[q], pq);
    const bool sheared = shear.regime != PointShear::Regime::none;
    for (size_t k = 0; k < sp.nodes.size(); ++k) {
      force.segment<2>(2 * sp.nodes[k]) -= pq * sp.weight * sp.values(static_cast<Eigen::Index>(k)) * g[q].normal;
      if (sheared) {
        force.segment<2>(2 * sp.nodes[k]) -= shear.shear * sp.weight * sp.values(static_cast<Eigen::Index>(k)) * unit_tangent(g[q]);
      }
    }
    if (tangent == nullptr) continue;
    // Σ_q P_q w_q R_b R_c ∂²g/∂x² (the turning of the tool's normal), and for the shear
    // −w_q R_b R_c (τ ∂t/∂x + t ⊗ ∂τ/∂x) with ∂τ/∂x of stick (slip's ∂τ/∂P comes below).
    Eigen::Matrix2d shear_block = Eigen::Matrix2d::Zero();
    if (sheared) {
      shear_block = -shear.shear * unit_tangent_gradient(g[q]);
      if (shear.regime == PointShear::Regime::stick) shear_block -= unit_tangent(g[q]) * shear.shear_gradient.transpose();
    }
    for (size_t b = 0; b < sp.nodes.size(); ++b) {
      for (size_t c = 0; c < sp.nodes.size(); ++c) {
        const double rr = sp.values(static_cast<Eigen::Index>(b)) * sp.values(static_cast<Eigen::Index>(c));
        Eigen::Matrix2d k = pq * sp.weight * sp.values(static_cast<Eigen::Index>(b)) *
                            sp.values(static_cast<Eigen::Index>(c)) * g[q].hessian;
        if (sheared) k += sp.weight * rr * shear_block;
        add_block(sp.nodes[b], sp.nodes[c], k);
      }
    }
    if (shear.regime != PointShear::Regime::slip || shear.limit_slope == 0.0) continue;
    // Slip at a limit L(P_q) (μ_a P_q for Coulomb): τ = s L, ∂P_q/∂u = Σ_a N_a(q) ε G_a:
    // −w_q R_b s L′ ε N_a(q) t ⊗ G_a.
    const Eigen::Vector2d t = unit_tangent(g[q]);
    for (size_t k = 0; k < sp.nodes.size(); ++k) {
      const auto a = static_cast<size_t>(sp.multipliers[k]);
      if (gradients[a].empty()) continue;  // an inactive node adds nothing to P_q
      const double scale = -sp.weight * shear.slip_sign * shear.limit_slope * penalty_ *
                           sp.values(static_cast<Eigen::Index>(k));
      for (size_t b = 0; b < sp.nodes.size(); ++b) {
        for (const auto& [c, gc] : gradients[a]) {
          add_block(sp.nodes[b], c, scale * sp.values(static_cast<Eigen::Index>(b)) * t * gc.transpose());
        }
      }
    }
  }
  if (tangent == nullptr) return true;
  // ε A_a G_a G_aᵀ for every active node: the normal pressure's own change.
  for (size_t a = 0; a < surface_nodes_.size(); ++a) {
    const double scale = penalty_ * node_area_[a];
    for (const auto& [b, gb] : gradients[a]) {
      for (const auto& [c, gc] : gradients[a]) add_block(b, c, scale * gb * gc.transpose());
    }
  }
  return true;
}

ContactState MortarContact::state(const Eigen::VectorXd& u) const {
  ContactState s;
  bool ok = true;
  std::string reason;
  std::vector<Eigen::Vector2d> positions;
  const std::vector<PointGap> g = gaps(u, s.projections, reason, ok, &positions);
  if (!ok) throw Error(reason);
  const Eigen::VectorXd p = node_pressures(g);
  s.surface_length = surface_length_;
  for (size_t q = 0; q < points_.size(); ++q) {
    const auto& sp = points_[q];
    const double pq = point_pressure(q, p);
    const PointShear shear = pq > 0.0 ? point_shear(q, g[q], pq) : PointShear{};
    s.point_x.push_back(sp.position.x());
    s.point_weight.push_back(sp.weight);
    s.point_position.push_back(positions[q]);
    s.point_pressure.push_back(std::max(pq, 0.0));
    s.point_shear.push_back(shear.shear);
    s.point_normal.push_back(g[q].normal);
    s.point_gap.push_back(g[q].evaluated ? std::optional<double>(g[q].gap) : std::nullopt);
    s.point_wetted.push_back(wetted(q) ? 1 : 0);
    if (pq <= 0.0) continue;
    if (wetted(q)) s.wetted_contact_length += sp.weight;
    s.force += pq * sp.weight * g[q].normal;  // the tool pushes the chip along its outward normal
    if (shear.regime != PointShear::Regime::none) s.force += shear.shear * sp.weight * unit_tangent(g[q]);
    s.contact_length += sp.weight;
    s.max_pressure = std::max(s.max_pressure, pq);
  }
  return s;
}

}  // namespace mufric::contact
