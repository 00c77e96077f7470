#pragma once
// Penalty contact between the chip's top surface and a rigid tool, frictionless or with an interface
// law (interface_laws.hpp; dry or wetted spots), in the mortar
// knot-to-surface form of seed 000 eq. (14)–(16) (Temizer, Wriggers & Hughes, CMAME 200, 2011;
// Dimitri et al., CMAME 269, 2014): the normal gap of every surface quadrature point to its closest
// point on the tool, g = (x_p − x_q)·n_p (positive when the chip penetrates the tool), is averaged
// per surface control point with its basis function, g_a = ∫N_a g dΓ / ∫N_a dΓ, and the control
// point carries the pressure p_a = ε⟨g_a⟩. Integrals are over the reference surface. The tangent is
// the exact linearisation, including the curvature of the tool.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "micro/contact/interface_law.hpp"
#include "micro/solid/solid_problem.hpp"
#include "micro/spline/closest_point.hpp"

namespace mufric::contact {

// Penalty factor of seed 000 section 4, Pa/m.
inline constexpr double kDefaultPenalty = 2e18;

// The interfacial shear at the contact points is an InterfaceLaw (interface_laws.hpp: frictionless,
// Coulomb, shear factor, Zorev, an adhesion table, Childs), asked for each point's slip limit. Stick
// is regularised by a tangential penalty with a return map (Wriggers, Computational Contact
// Mechanics, 2nd ed. 2006, §5.2.2; Laursen 2002 §5.3): trial τ = −ε_t g_t from the point's tangential
// offset g_t to its anchor on the tool, slip when |τ| exceeds the law's limit, the anchor moved at
// each accepted step.
// Stick's tangential penalty as a fraction of the normal one: a stuck point's offset τ/ε_t stays
// sub-nanometre (0.5 nm at τ = 100 MPa, ε = 2e18), and Newton needs a third of the iterations it
// needs at ε_t = ε (small default scene with μ_a = 0.1: 545 against 1299; μ within 0.6 %).
inline constexpr double kTangentialPenaltyRatio = 0.1;

// The share of the frictional heat that enters the chip (the rest goes into the tool, which the
// micro-model does not conduct). At the micro-model's scale the Péclet number of the sliding chip is
// small (v a / 2κ ≈ 0.06 at 100 m/min over a 1 µm contact spot, κ = 1.4e-5 m²/s for steel), and
// Blok's partition for slow sliding then shares the heat in the ratio of the conductivities, k_chip /
// (k_chip + k_tool) (Blok 1937, Proc. General Discussion on Lubrication, IMechE 2:222; Kennedy 1984,
// J. Tribol. 106:145): 0.33–0.71 for a steel chip (~50 W/(m K)) on WC–Co (~50–100) or a TiN coating
// (~20). The middle of that range is the default; the scene sets it (contact.heat_partition).
inline constexpr double kDefaultHeatPartition = 0.5;
inline constexpr CoefficientRange kHeatPartitionRange{0.0, 1.0};

// The law and what the contact does around it, whatever the law: stick's regularisation and where
// the frictional heat goes.
struct ContactInterface {
  std::shared_ptr<const InterfaceLaw> law;  // none: frictionless
  double tangential_penalty = 0.0;          // ε_t, Pa/m; 0: kTangentialPenaltyRatio × the normal penalty
  double heat_partition = kDefaultHeatPartition;  // β: the share of the interface's frictional heat the chip receives
  bool operator==(const ContactInterface& o) const {
    const bool same_law = law && o.law ? law->same_as(*o.law) : law == o.law;
    return same_law && tangential_penalty == o.tangential_penalty && heat_partition == o.heat_partition;
  }
};

// The rigid tool: a curve whose outward normal, for a curve running in +x, points down (−y side),
// toward the chip below it. Periodic tools repeat with their shift (the interval).
struct RigidTool {
  spline::SplineCurve surface;
  double lowest_y() const;  // below every point of the tool (its control polygon's lowest point)
};

// What the contact transmits at a displacement: the resultant force on the chip (eq. 17's
// numerator and denominator), contact area, peak pressure.
struct ContactState {
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  // ∫ T dΓ on the chip, N per unit depth
  double contact_length = 0.0;                      // reference length where the pressure is > 0, m
  double surface_length = 0.0;                      // reference length of the chip surface, m
  double max_pressure = 0.0;                        // Pa
  int projections = 0;                              // closest-point searches done
  // Per surface quadrature point, for output and tests: reference x, reference length dΓ, current
  // position, pressure, shear (along the tool's unit tangent, which runs with the curve, +x for a
  // profile), the tool's normal at the closest point, and the gap (positive when the chip
  // penetrates; none where the point is too far from the tool to be searched).
  std::vector<double> point_x, point_weight, point_pressure, point_shear;
  std::vector<Eigen::Vector2d> point_position, point_normal;
  std::vector<std::optional<double>> point_gap;
  // Per point, whether it takes the law's wetted coefficients (its PointStateProvider says), and the reference length of the points
  // in contact that do.
  std::vector<char> point_wetted;
  double wetted_contact_length = 0.0;
};

class MortarContact final : public solid::BoundaryInteraction {
 public:
  // The chip surface is the patch's top side; `points_per_span` Gauss points per span.
  MortarContact(const solid::IgaSpace& space, RigidTool tool, double penalty = kDefaultPenalty, int points_per_span = 0,
                ContactInterface contact_interface = {});

  std::vector<std::vector<int>> coupled_nodes() const override;
  bool add(const Eigen::VectorXd& u, Eigen::VectorXd& force, solid::TangentAccumulator* tangent,
           std::string& reason) const override;
  // Slip makes the tangent unsymmetric; the frictionless one is symmetric.
  bool symmetric_tangent() const override { return !interface_.law->frictional(); }
  // Moves each contact point's anchor to where the accepted state leaves it (stick: kept; slip: the
  // return map's; out of contact: its current foot, so that a new contact starts stress-free).
  // Also adds up the energy each point dissipated by slipping in the step just accepted.
  void commit(const Eigen::VectorXd& u) override;
  // Energy dissipated at the interface by the interfacial law, J per unit depth: since construction,
  // and in the last accepted step. Per point it is |τ| times the slip of the return map (the anchor's
  // move), w_q |τ| (|τ_trial| − |τ|)/ε_t, the backward-Euler dissipation of the regularised law.
  double dissipated_energy() const { return dissipated_energy_; }
  double step_dissipated_energy() const { return step_dissipated_energy_; }
  // The heat the chip receives from the last accepted step's slip, per node of the chip's space
  // (J per unit depth, node_count entries): β w_q D_q distributed with the surface basis R_b.
  Eigen::VectorXd frictional_heat(Eigen::Index node_count) const;
  // Where each point's state beyond its pressure comes from (the chip's k and T beneath it, whether the
  // lubricant wets it): needed before the first step by a law whose needs() asks for k or T.
  void set_point_states(std::shared_ptr<const PointStateProvider> states) { states_ = std::move(states); }
  bool wetted(size_t point) const { return states_ && states_->state(point).wetted; }
  // Reference position of each surface quadrature point.
  std::vector<Eigen::Vector2d> surface_positions() const;
  // Each surface point's position at the last commit (a frictional law's; empty before the first).
  const std::vector<Eigen::Vector2d>& committed_positions() const { return committed_positions_; }
  ContactState state(const Eigen::VectorXd& u) const;
  const RigidTool& tool() const { return tool_; }
  double penalty() const { return penalty_; }
  const InterfaceLaw& law() const { return *interface_.law; }
  const ContactInterface& contact_interface() const { return interface_; }

 private:
  struct SurfacePoint {
    std::vector<int> nodes;    // nodes with non-zero basis value here
    Eigen::VectorXd values;    // R_b
    double weight;             // dΓ (reference)
    Eigen::Vector2d position;  // X
    std::vector<int> multipliers;  // index of each node in the surface-node list (for N_a)
  };
  struct PointGap {
    bool evaluated = false;
    double gap = 0.0;  // g, m
    Eigen::Vector2d normal = Eigen::Vector2d::Zero();  // tool's outward normal at the foot
    Eigen::Matrix2d hessian = Eigen::Matrix2d::Zero(); // ∂²g/∂x²
    double parameter = 0.0;                            // ξ of the foot
    Eigen::Vector2d d1 = Eigen::Vector2d::Zero(), d2 = Eigen::Vector2d::Zero();  // C′(ξ), C″(ξ)
    Eigen::Vector2d parameter_gradient = Eigen::Vector2d::Zero();  // ∂ξ/∂x
  };
  // The shear at a contact point and what its tangent needs: τ along the unit tangent t = C′/|C′|.
  struct PointShear {
    enum class Regime { none, stick, slip } regime = Regime::none;
    double shear = 0.0;                                     // τ, Pa
    double trial = 0.0;                                     // the trial shear −ε_t g_t, Pa (its slip: |trial| − |τ| over ε_t)
    Eigen::Vector2d shear_gradient = Eigen::Vector2d::Zero();  // stick: ∂τ/∂x
    double slip_sign = 0.0;                                 // slip: τ = slip_sign × the limit
    double limit_slope = 0.0;  // slip: ∂(limit)/∂P from the law (0 where it does not depend on P in a step)
  };
  PointShear point_shear(size_t q, const PointGap& g, double pressure) const;
  // Why the law cannot be asked yet (its provider lacks what it needs); none when it can.
  std::optional<std::string> missing_point_state() const;
  // The tool's unit tangent at a point's foot and its derivative with respect to the point's position.
  static Eigen::Vector2d unit_tangent(const PointGap& g) { return g.d1.normalized(); }
  static Eigen::Matrix2d unit_tangent_gradient(const PointGap& g);
  // Gaps at every point whose surface node could be in contact; the rest stay unevaluated.
  std::vector<PointGap> gaps(const Eigen::VectorXd& u, int& projections, std::string& reason, bool& ok,
                             std::vector<Eigen::Vector2d>* positions = nullptr) const;
  Eigen::VectorXd node_pressures(const std::vector<PointGap>& g) const;  // p_a per surface node
  // The mortar pressure at a point, P_q = Σ_a p_a N_a(q).
  double point_pressure(size_t q, const Eigen::VectorXd& node_pressure) const;

  // The tool as a graph over x (when it is one): dense samples (x, y, u) over one period, used to
  // bound each closest-point search to the spans within the point's vertical distance.
  struct GraphSample {
    double x, y, u;
  };
  spline::ProjectionOptions search_window(const Eigen::Vector2d& x) const;

  RigidTool tool_;
  ContactInterface interface_;
  std::shared_ptr<const PointStateProvider> states_;
  // Per surface point, the tool parameter where its tangential offset is zero (committed state);
  // none where the point was not searched at the last commit.
  std::vector<std::optional<double>> anchor_;
  std::vector<Eigen::Vector2d> committed_positions_;  // at the last commit (frictional laws)
  std::vector<double> step_dissipation_;  // per surface point, J/m, in the last accepted step
  double step_dissipated_energy_ = 0.0, dissipated_energy_ = 0.0;
  std::shared_ptr<const spline::ProjectionSeeds> seeds_;  // the tool's seeding samples, computed once
  double penalty_;
  std::vector<GraphSample> graph_;  // empty: the tool is not a graph over x, search globally
  std::vector<SurfacePoint> points_;
  std::vector<int> surface_nodes_;         // global node of each surface node a
  std::vector<double> node_area_;          // A_a = ∫ N_a dΓ
  // The points in the support of N_a, each with N_a's position in that point's node list.
  struct SupportPoint {
    int point, local;
  };
  std::vector<std::vector<SupportPoint>> node_points_;
  double surface_length_ = 0.0;
};

}  // namespace mufric::contact
