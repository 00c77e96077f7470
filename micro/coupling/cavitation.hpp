#pragma once
// A liquid film cannot hold tension: where it would pull the wall with a pressure below the
// cavitation pressure p_c, it cavitates — a cavity at p_c opens between liquid and wall and the
// liquid no longer follows the wall. In the thin film between rough surfaces this happens locally,
// where the gap diverges behind a passing asperity (the classic Reynolds-wedge suction), while the
// converging side stays pressurised, so the state is kept per wall sample, mass-conserving as in the
// Jakobsson–Floberg–Olsson theory (Elrod, J. Lubr. Technol. 103, 1981): a cavitated sample carries
// the cavity's area, which grows as the wall moves away from the liquid at (g − v)·n (g the wall's,
// v the liquid's velocity, n out of the liquid), and the sample refills when it is back to zero.
// While cavitated the liquid's wall side is a traction side at p_c and the wall feels −p_c n.
// A full sample cavitates when its liquid pulls, σn·n > −p_c. States change between accepted steps
// (explicitly, one step late, like a contact state updated after the step), so each step's coupled
// map stays smooth for the interface quasi-Newton iteration.
#include <cstddef>
#include <vector>

namespace mufric::coupling {

// A cavity thinner than this (m, far below an atom) is closed: the round-off of its growth summed over steps.
inline constexpr double kClosedCavityThickness = 1e-15;

// One wall sample of the film: the film's thickness there (m, across x: the film's columns are
// vertical), the width along x and the length of wall it stands for (the wall is sloped, so a cavity
// of normal thickness c takes c × wall_length), whether it is a contact spot (between pockets), the
// liquid's normal stress on the wall σn·n (Pa, > 0 pulls) and the rate at which the wall leaves the
// liquid, (g − v)·n (m/s).
struct FilmSample {
  double film = 0.0;         // m
  double width = 0.0;        // m along x
  double wall_length = 0.0;  // m along the wall
  bool spot = false;
  double normal_stress = 0.0;
  double opening_rate = 0.0;
};

// The pockets of a periodic row of samples: runs between spots, the last run continuing into the
// first; without any spot, the whole row is one pocket.
std::vector<std::vector<size_t>> pocket_runs(const std::vector<FilmSample>& samples);

// The contact spots the lubricant reaches: a run of spot samples is wetted, all of it, when the
// pocket sample at either of its ends has liquid against the wall (`liquid_at_wall`, per sample: not
// cavitated) — the liquid at a junction's edge is drawn into it by capillarity and forms a boundary
// film over it (Williams & Tabor 1977, Wear 43:275; Williams 1977, J. Mech. Eng. Sci. 19:202). A row
// without pockets has no edge for liquid: no spot is wetted. Per sample, 1 where wetted.
std::vector<char> wetted_spots(const std::vector<FilmSample>& samples, const std::vector<char>& liquid_at_wall);

// The liquid's volume is the film's area less its cavities' and is kept by the books: the cavities
// are areas (m² per unit depth) at the wall samples, grown by the wall's opening rate times the
// sample's wall length (a thickness times a length that changes as the chip's surface stretches
// booked area the liquid never left: 8e-14 m² per m against a 1.8e-13 liquid), and where a cavity
// closes within a step the liquid that ran on past the wall — the sample was a traction side for the
// whole step, an error of switching states between steps, O(Δt) — fills the nearest cavities instead,
// as a volume-of-fluid scheme hands an overfilled cell's excess to its neighbours (dropped, it lost
// 17 % of the liquid over the coarse study run; forcing the closing sample's liquid onto the wall
// instead demanded pressures the coupling did not converge under). RESULTS, "The lubricant, fifth pass".
class CavitatingFilm {
 public:
  // within_gap: a cavity grows to the gap it is in and no further, the column then empty — for a film
  // whose liquid also leaves out of the plane (a leak), where the wall goes on leaving liquid that has
  // already gone (without the bound the liquid went to −1.1e-13 m²/m at 1300 MPa on the coarse box).
  // A sealed film keeps its books only unbounded: its liquid left the column along the film, which the
  // neighbouring full columns hold (bounded, the trapped-film test's liquid grew by 3 % of itself).
  explicit CavitatingFilm(double cavitation_pressure, bool within_gap = false)
      : p_c_(cavitation_pressure), within_gap_(within_gap) {}
  double cavitation_pressure() const { return p_c_; }
  bool cavitated(size_t sample) const { return sample < cavitated_.size() && cavitated_[sample] != 0; }
  // A film just formed: its contact spots hold no liquid — the minimum layer kept there is space,
  // not lubricant — so they start as cavities as large as the layer; the rest is full.
  void form(const std::vector<FilmSample>& samples);
  // After an accepted step of length dt: the samples' states for the next step.
  void update(const std::vector<FilmSample>& samples, double dt);
  double cavity_area() const { return cavity_area_; }              // m² per unit depth, after update()
  double cavitated_fraction() const { return cavitated_fraction_; }  // of the wall's length
  // The liquid (m² per unit depth) that ran past the wall where cavities closed in the last update()'s
  // step, and of that what no cavity could take (lost: only when no sample is cavitated).
  double closing_overshoot() const { return closing_overshoot_; }
  double lost_overshoot() const { return lost_overshoot_; }
  // What the gap bound cut off the cavities' growth in the last update() (m² per unit depth).
  double overgrowth() const { return overgrowth_; }

 private:
  void tally(const std::vector<FilmSample>& samples);  // cavity_area_ and cavitated_fraction_ from the states
  double p_c_;
  bool within_gap_ = false;
  double overgrowth_ = 0.0;
  std::vector<char> cavitated_;
  std::vector<double> cavity_;  // m² per unit depth at each cavitated sample
  double cavity_area_ = 0.0, cavitated_fraction_ = 0.0, closing_overshoot_ = 0.0, lost_overshoot_ = 0.0;
};

}  // namespace mufric::coupling
