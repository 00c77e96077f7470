#pragma once
// The lubricant's options as a scene states them (the `lubricant` section): the liquid, the film's
// mesh and how it forms, cavitation, the out-of-plane leak and the coupling's iteration, with their
// defaults (seed 000 Table 2 and the studies in bench/studies/lubricant/README.md), their reader, and what the
// coupling makes of them with what the run knows (the chip's mass, its first step, when sliding
// starts, the applied pressure). The scene only composes these; a lubricant option is added here and
// nowhere else.
#include <optional>

#include "micro/coupling/lubricated_chip.hpp"
#include "micro/settings/option_keys.hpp"

namespace mufric::coupling {

enum class Compressibility { none, linear, dowson_higginson };
enum class FilmFill { gap, after_pressing };
enum class CavitationModel { none, mass_conserving };
enum class LeakModel { none, ambient, cell_mean };

// The lubricant in the pockets (physics "lubricated"; ignored by a dry run, so one scene serves both).
struct LubricantSettings {
  double density = 800.0;      // kg/m³ (seed 000 Table 2)
  double viscosity = 0.032;    // Pa s (seed 000 Table 2)
  // "none" (incompressible, seed 000), "linear" (ρ/ρ₀ = 1 + p/K₀) or "dowson-higginson" (ρ/ρ₀ =
  // 1 + (p/K₀)/(1 + 1.7 GPa⁻¹ p)); K₀ the bulk modulus at p = 0, Dowson & Higginson's 1/(0.6 GPa⁻¹) by
  // default (fluid::FluidProperties).
  Compressibility compressibility = Compressibility::none;
  double bulk_modulus = fluid::kDowsonHigginsonBulkModulus;  // Pa
  int elements_x = 0;          // film columns; 0: the chip's discretisation.elements_x
  int elements_y = 4;          // elements across the film
  // m, the film where the chip touches the tool. 20 nm: thinner ones (5, 10 nm) stop the coarse
  // scene's coupling, 20 and 40 nm give μ within 4 % of each other (bench/studies/lubricant/README.md).
  double min_film = 20e-9;
  // What the film holds: "gap", all the lubricant in the initial gap from t = 0 (seed-000 protocol's
  // default: it carries the load and no contact forms); "after-pressing" (press-slide's default), the
  // chip pressed dry (the lubricant drained) and the film formed in the gap it leaves when sliding starts.
  FilmFill fill = FilmFill::after_pressing;
  // Tension in the film: "none", the liquid holds any (seed 000's model); "mass-conserving", where the
  // liquid would pull the chip below cavitation_pressure a cavity opens (cavitation.hpp).
  CavitationModel cavitation = CavitationModel::mass_conserving;
  double cavitation_pressure = 0.0;  // Pa, relative to the ambient zero of the applied load
  // Liquid flowing out of the plane of the cell (LubricantOptions::leak): "none", sealed in
  // it (seed 000's protocol's default); "ambient" (press-slide's default), draining toward the ambient
  // zero; "cell-mean", moving between the film's parts toward its mean pressure (the film keeps its
  // liquid). Over leak_length either side of the slice. Decided from a study (README, "The lubricant";
  // bench/studies/lubricant/README.md, "The lubricant, eighth pass").
  LeakModel leak = LeakModel::ambient;
  double leak_length = 1e-6;  // m: about the roughness' correlation length (tool 0.8 µm, chip 1 µm)
  // Minimum films over which the fluid's load fades out into a contact spot (a continuous switch).
  double contact_fade = 2.0;
  // α_R, Pa s/m; 0: the automatic ρ_chip h_chip / max(Δt, time.step) + robin_stiffness Δt.
  double robin_weight = 0.0;
  double robin_stiffness = 0.0;  // β, Pa/m: the chip's stiffness in the automatic α_R (lubricated_chip.hpp)
  // How the film's interior follows its walls: "columns" (algebraic, cannot fold) or "elastic" (EMUM,
  // with mesh_stiffening the χ of its Jacobian-based stiffening); micro/coupling/lubricated_chip.hpp.
  FilmMeshMotion mesh_motion = FilmMeshMotion::columns;
  double mesh_stiffening = 1.0;
  Acceleration acceleration = Acceleration::iqn_ils;  // iqn-ils, aitken or relaxation
  double relaxation = 0.5;
  int reuse_steps = 8;
  double qr_filter = 1e-8;
  // Relative, of the interface load and displacement. The chip's own Newton tolerance, amplified by α_R/Δt,
  // leaves the load a noise floor near 1e-4 of its size once the chip yields; with contact spots
  // opening and closing beside the film the iteration stalls near 1e-3 at some points of the box, and
  // 3e-3 moves μ by 0.4 % where both converge (bench/studies/lubricant/README.md).
  double coupling_tolerance = 3e-3;
  // Of load.pressure: the interface traction's change, as a root mean square over the film's wall
  // samples, below this is converged whatever the film's own traction (CouplingOptions::load_tolerance).
  // Its force on the chip then errs by at most this share of the applied load. 0: the relative
  // coupling_tolerance alone. Ignored with a displacement-controlled load (no pressure to scale by).
  double traction_tolerance = 3e-4;
  // The liquid a step's mismatch of interface velocities (fluid against film wall, (λ − λ̃)/α_R)
  // moves through the wall, over the film's volume. The traction tolerance alone left it at up to
  // 2 % per step and μ 8 % off; 1e-3 puts μ within 0.6 % of 1e-5 (bench/studies/lubricant/README.md).
  double volume_tolerance = 1e-3;
  int max_coupling_iterations = 50;
  // Exchanges without a new best traction change after which a step fails and is cut back (0: never).
  int stall_iterations = 0;
  // Restarts of a step's interface iteration after a solver failed on an accelerated iterate,
  // before the step fails and is cut back (CouplingOptions::max_restarts).
  int coupling_restarts = 0;
  // Reads the section; `press_slide`: the protocol presses first (the defaults of fill and leak follow it).
  static LubricantSettings read(OptionKeys& keys, bool press_slide);
  bool operator==(const LubricantSettings&) const = default;
};


// What the run adds to the settings: the chip's resolution and mass, its time step, when sliding
// starts, and the pressure a traction tolerance is scaled by (none: a displacement-controlled load).
struct LubricantRun {
  int chip_elements_x = 0;
  double chip_mass_per_area = 0.0;  // kg/m²
  double first_step = 0.0;          // s: the shortest α_R step
  double slide_start = 0.0;         // s
  std::optional<double> applied_pressure;  // Pa
};
LubricantOptions lubricant_options(const LubricantSettings& settings, const LubricantRun& run);

}  // namespace mufric::coupling

MUFRIC_OPTION_WORDS(coupling::Compressibility, {"none", coupling::Compressibility::none},
                    {"linear", coupling::Compressibility::linear},
                    {"dowson-higginson", coupling::Compressibility::dowson_higginson})
MUFRIC_OPTION_WORDS(coupling::FilmFill, {"gap", coupling::FilmFill::gap},
                    {"after-pressing", coupling::FilmFill::after_pressing})
MUFRIC_OPTION_WORDS(coupling::CavitationModel, {"none", coupling::CavitationModel::none},
                    {"mass-conserving", coupling::CavitationModel::mass_conserving})
MUFRIC_OPTION_WORDS(coupling::LeakModel, {"none", coupling::LeakModel::none},
                    {"ambient", coupling::LeakModel::ambient}, {"cell-mean", coupling::LeakModel::cell_mean})
MUFRIC_OPTION_WORDS(coupling::FilmMeshMotion, {"columns", coupling::FilmMeshMotion::columns},
                    {"elastic", coupling::FilmMeshMotion::elastic})
MUFRIC_OPTION_WORDS(coupling::Acceleration, {"iqn-ils", coupling::Acceleration::iqn_ils},
                    {"aitken", coupling::Acceleration::aitken},
                    {"relaxation", coupling::Acceleration::constant_relaxation})
