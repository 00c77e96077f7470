#pragma once
// A liquid film cannot hold tension: where it would pull the wall with a pressure below the
// cavitation pressure p_c, it cavitates — a cavity at p_c opens between liquid and wall and the
// liquid no longer follows the wall. In the thin film between rough surfaces this happens locally,
// where the gap diverges behind a passing asperity (the classic Reynolds-wedge suction), while the
// converging side stays pressurised, so the state is kept per wall sample, mass-conserving as in the
// Jakobsson–Floberg–Olsson theory (Elrod, J. Lubr. Technol. 103, 1981): a cavitated sample carries
// the cavity's thickness c ≥ 0, which grows as the wall moves away from the liquid, ċ = (g − v)·n
// (g the wall's, v the liquid's velocity, n out of the liquid), and the sample refills when c is back
// to zero. While cavitated the liquid's wall side is a traction side at p_c and the wall feels −p_c n.
// A full sample cavitates when its liquid pulls, σn·n > −p_c. States change between accepted steps
// (explicitly, one step late, like a contact state updated after the step), so each step's coupled
// map stays smooth for the interface quasi-Newton iteration.
#include <cstddef>
#include <vector>

namespace mufric::coupling {

// A cavity thinner than this (m, far below an atom) is closed: the round-off of ċ summed over steps.
inline constexpr double kClosedCavityThickness = 1e-15;

// One wall sample of the film: the film's thickness there and the length it stands for, whether it
// is a contact spot (between pockets), the liquid's normal stress on the wall σn·n (Pa, > 0 pulls)
// and the rate at which the wall leaves the liquid, (g − v)·n (m/s).
struct FilmSample {
  double film = 0.0;    // m
  double length = 0.0;  // m
  bool spot = false;
  double normal_stress = 0.0;
  double opening_rate = 0.0;
};

// The pockets of a periodic row of samples: runs between spots, the last run continuing into the
// first; without any spot, the whole row is one pocket.
std::vector<std::vector<size_t>> pocket_runs(const std::vector<FilmSample>& samples);

class CavitatingFilm {
 public:
  explicit CavitatingFilm(double cavitation_pressure) : p_c_(cavitation_pressure) {}
  double cavitation_pressure() const { return p_c_; }
  bool cavitated(size_t sample) const { return sample < cavitated_.size() && cavitated_[sample] != 0; }
  // A film just formed: its contact spots hold no liquid — the minimum layer kept there is space,
  // not lubricant — so they start as cavities as thick as the layer; the rest is full.
  void form(const std::vector<FilmSample>& samples);
  // After an accepted step of length dt: the samples' states for the next step.
  void update(const std::vector<FilmSample>& samples, double dt);
  double cavity_area() const { return cavity_area_; }              // m² per unit depth, after update()
  double cavitated_fraction() const { return cavitated_fraction_; }  // of the wall's length

 private:
  void tally(const std::vector<FilmSample>& samples);  // cavity_area_ and cavitated_fraction_ from the states
  double p_c_;
  std::vector<char> cavitated_;
  std::vector<double> cavity_;  // m, the cavity's thickness at each cavitated sample
  double cavity_area_ = 0.0, cavitated_fraction_ = 0.0;
};

}  // namespace mufric::coupling
