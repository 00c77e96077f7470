#pragma once
// The lubricated chip: the chip's time steps coupled, Robin–Neumann and strongly, with the lubricant
// film between it and the rigid tool (seed 000 sec. 2.2–2.3). Per step the coupling iterates on the
// film's traction on the chip: the chip is solved under it (a trial of the step), the film's mesh
// follows the chip's new surface (EMUM), and the fluid, with the Robin condition built from the
// chip's surface velocity and that traction, returns a new traction; IQN-ILS accelerates it.
// Where the film is at its minimum thickness the chip touches the tool: there the chip boundary
// carries contact, and the fluid's traction is not passed on (one interaction per location).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "micro/coupling/cavitation.hpp"
#include "micro/coupling/chip_interface.hpp"
#include "micro/coupling/partitioned.hpp"
#include "micro/fluid/mesh_update.hpp"
#include "micro/fluid/navier_stokes.hpp"
#include "micro/solid/time_integrator.hpp"

namespace mufric::coupling {

// A fluid point whose film is thinner than this many minimum films is (partly) a contact spot: its
// traction reaches the chip scaled from 1 here down to 0 at one minimum film (the default of
// LubricantOptions::contact_fade).
inline constexpr double kContactFilmFactor = 2.0;

// How the film's interior follows its moving walls. columns (the default): each column's control
// points stay spaced across the film as when it formed — it cannot fold (gap_net). elastic: the
// elastic mesh-update method with Jacobian-based stiffening (mesh_update.hpp), which let the interior
// drift sideways step after step until it folded under the ploughed chip (the default 64 × 12 scene
// stopped at 2.5 µm of 4.5; RESULTS, "The lubricant, fifth pass").
enum class FilmMeshMotion { columns, elastic };

struct LubricantOptions {
  fluid::FluidProperties fluid;      // seed 000 Table 2
  GapMeshOptions mesh;
  FilmMeshMotion mesh_motion = FilmMeshMotion::columns;
  fluid::MeshUpdateOptions mesh_update;  // for the elastic motion
  CouplingOptions coupling;
  // α_R of the Robin condition (Pa s/m); 0: the chip's mass per unit surface over the step being
  // taken, ρ_chip h_chip / Δt — the weight that makes the iteration exact for a rigid chip (the
  // piston test; Badia, Nobile & Vergara 2008) — but over no less than shortest_weight_step. A
  // cut-back step needs a larger weight than the full step: with the full step's the fluid's
  // incompressible response to a short step swamped it, and the coarse default scene stopped at
  // 2 µm of sliding. Without a floor the weight of a deep cut-back turns the Robin side into a
  // velocity side, which an enclosed film cannot follow (the tiny dataset scene failed its first
  // sliding step; fixed weights 1e6–1e8 Pa s/m pass it, 1e9 fails). RESULTS, "The lubricant,
  // fourth pass". IQN-ILS forgets past steps when Δt changes, so its secant pairs stay one map's.
  // The chip's stiffness enters as in Badia, Nobile & Vergara's generalized string model (J. Comput.
  // Phys. 227, 2008): α_R = ρ_chip h_chip / Δt + β Δt, β = robin_stiffness (Pa/m). Pressed on the
  // tool, the chip resists the film by its stiffness far more than by its inertia.
  double robin_weight = 0.0;
  double robin_stiffness = 0.0;      // β, Pa/m, for the automatic α_R
  double chip_mass_per_area = 0.0;   // kg/m², for the automatic α_R
  double shortest_weight_step = 0.0;  // s, for the automatic α_R (the scene's time.step)
  // When the film is formed: at t = 0 in the whole initial gap (0), or at this time from the gap the
  // chip leaves then — e.g. the start of sliding, the lubricant having drained while the chip was
  // pressed (the chip's steps before it are dry).
  double film_from = 0.0;            // s
  double contact_fade = kContactFilmFactor;  // minimum films over which the fluid's share fades (> 1)
  // The film cavitates where its liquid would pull the chip with a pressure below this (Pa;
  // cavitation.hpp); none: the liquid holds any tension (seed 000's model).
  std::optional<double> cavitation_pressure;
  // Whether the liquid also flows out of the plane of the cell: none, sealed in it (seed 000's 2D cell,
  // whose every valley is sealed by its first contact spot); otherwise by Poiseuille flow over
  // leak_length either side of the slice, κ = h²/(6ηL²) with h the film's local thickness
  // (fluid::out_of_plane_leak_coefficient), toward the ambient pressure 0 (the liquid drains) or
  // toward the film's mean pressure (it moves between pockets around the contact spots, as in a 3D
  // rough contact below percolation, and the film keeps its liquid). RESULTS, "The lubricant, eighth pass".
  std::optional<fluid::LeakTarget> leak;
  double leak_length = 1e-6;  // m
};

// α_R for a step of length dt: options.robin_weight when given, else the automatic weight.
double robin_weight(const LubricantOptions& options, double dt);

// What one accepted step did at the interface.
struct LubricatedStep {
  int coupling_iterations = 0;
  int coupling_restarts = 0;           // of the interface iteration after a solver failed (CouplingOptions::max_restarts)
  int fluid_newton_iterations = 0;     // summed over the coupling iterations
  double min_relative_jacobian = 1.0;  // of the film's mesh
  Eigen::Vector2d fluid_force = Eigen::Vector2d::Zero();  // on the chip, N per unit depth
  double film_area = 0.0;              // m² per unit depth: the lubricant's volume
  std::vector<double> pocket_areas;    // m² per unit depth, between contact spots (empty: no contact spot)
  double cavitated_fraction = 0.0;     // of the interface's length, cavitated for the next step
  double cavity_area = 0.0;            // m² per unit depth: the cavities' space, not filled by liquid
  double liquid_area = 0.0;            // m² per unit depth: the liquid's volume (the film's without cavitation)
  double volume_error = 0.0;           // liquid moved through the film's wall by the velocity mismatch, of the film
  double leaked_area = 0.0;            // m² per unit depth: liquid that left the plane in the step, net (LubricantOptions::leak)
  double exchanged_area = 0.0;         // m² per unit depth: liquid that moved out of the plane in one direction in the step
};

class LubricatedChip {
 public:
  // Adds the film's load to `problem` (a NodalLoad interaction) and builds the film between the
  // chip's initial surface and the tool (a periodic curve over the same interval, a graph over x).
  LubricatedChip(solid::SolidProblem& problem, const spline::SplineCurve& tool, LubricantOptions options);

  // The coupled step for TimeIntegrationOptions::coupled_step.
  bool step(solid::TimeIntegrator& integrator, double t0, double dt, std::string& reason);

  const std::vector<LubricatedStep>& history() const { return history_; }
  const fluid::NavierStokes& fluid() const { return *fluid_; }
  // The film's area (m² per unit depth) when it formed (0 before).
  double formed_film_area() const { return formed_film_area_; }
  double formed_liquid_area() const { return formed_liquid_area_; }  // the film's less its cavities', when formed
  // Whether the film wets the contact spot at x (current position along the chip, any period): the
  // film sample nearest x is a wetted spot (wetted_spots) after the last accepted step. None is before
  // the film forms.
  bool wetted_at(double x) const;
  // The film's traction on the chip transferred in the last accepted step, as nodal forces.
  const Eigen::VectorXd& nodal_forces() const { return load_->forces(); }

 private:
  bool structure(solid::TimeIntegrator& integrator, double t0, double dt, const Eigen::VectorXd& traction,
                 Eigen::VectorXd& displacement, std::string& reason);
  bool film(const Eigen::VectorXd& displacement, const Eigen::VectorXd& traction, double dt, Eigen::VectorXd& new_traction,
            std::string& reason);
  // The film's net onto new bottom and top rows (gap_boundary_rows), by the options' mesh motion.
  fluid::MeshMoveReport move_film_mesh(const Eigen::MatrixX2d& rows);
  Eigen::VectorXd transfer(const Eigen::VectorXd& traction) const;  // the film's traction → chip nodal forces
  double contact_share(double film) const;  // of the film's traction that reaches the chip, at this thickness
  Eigen::VectorXd load_share() const;       // per traction component of the bottom side, of the current film mesh
  std::vector<FilmSample> film_samples() const;  // the film's bottom side, for pockets and cavitation
  size_t sample_at(double parameter) const;      // the bottom side sample at a curve parameter
  static std::vector<double> pocket_areas(const std::vector<FilmSample>& samples);
  double film_thickness(const fluid::ParametricPoint& bottom_point) const;  // m, tool minus chip above it
  double liquid_area() const;  // m² per unit depth: the film's less its cavities'
  void update_leak();          // κ over the film's columns, for the film's current thickness
  void form_film();  // the film in the gap the chip's surface (surface_) leaves now

  solid::SolidProblem& problem_;
  spline::SplineCurve tool_curve_;
  LubricantOptions options_;
  std::unique_ptr<ChipSurface> surface_;
  std::unique_ptr<PeriodicGraph> tool_;
  std::shared_ptr<NodalLoad> load_;
  std::unique_ptr<fluid::NavierStokes> fluid_;
  fluid::MeshUpdate mesh_update_;
  InterfaceAccelerator accelerator_;
  std::vector<int> bottom_nodes_, top_nodes_;  // of the film's patch
  std::vector<double> bottom_parameters_;      // of its bottom side's Gauss points (for the Robin traction)
  Eigen::VectorXd traction_;                   // σn on the film's bottom side points (2 per point), last step
  Eigen::VectorXd mesh_start_;                 // film mesh displacement at the start of the step
  std::vector<double> leak_coefficients_;      // κ at the bottom side's points, of the current film mesh
  std::vector<LubricatedStep> history_;
  LubricatedStep current_;
  std::optional<CavitatingFilm> cavitation_;  // with a cavitation pressure
  // The last exchange's liquid at the bottom samples: σn·n, and (g − v)·n, the chip leaving it.
  std::vector<double> normal_stress_, opening_rate_;
  double last_accepted_dt_ = 0.0;
  double mismatch_area_ = 0.0;  // m² per unit depth, signed: the last fluid solve's liquid through the full wall
  double volume_error_ = 0.0;  // liquid the last fluid solve's velocity mismatch makes in the step, relative
  std::vector<char> wetted_;  // per bottom sample, wetted spots after the last accepted step (empty: none)
  bool film_formed_ = false;
  double formed_film_area_ = 0.0, formed_liquid_area_ = 0.0;
};

}  // namespace mufric::coupling
