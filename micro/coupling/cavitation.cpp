#include "micro/coupling/cavitation.hpp"

namespace mufric::coupling {

std::vector<std::vector<size_t>> pocket_runs(const std::vector<FilmSample>& samples) {
  std::vector<std::vector<size_t>> runs;
  const size_t n = samples.size();
  size_t first_spot = n;
  for (size_t q = 0; q < n; ++q) {
    if (samples[q].spot) {
      first_spot = q;
      break;
    }
  }
  if (first_spot == n) {
    if (n > 0) {
      runs.emplace_back();
      for (size_t q = 0; q < n; ++q) runs.back().push_back(q);
    }
    return runs;
  }
  // Walk once around the period starting after the first spot, so the run across the end is whole.
  std::vector<size_t> open;
  for (size_t k = 1; k <= n; ++k) {
    const size_t q = (first_spot + k) % n;
    if (samples[q].spot) {
      if (!open.empty()) runs.push_back(std::move(open));
      open.clear();
    } else {
      open.push_back(q);
    }
  }
  if (!open.empty()) runs.push_back(std::move(open));
  return runs;
}

void CavitatingFilm::form(const std::vector<FilmSample>& samples) {
  cavitated_.assign(samples.size(), 0);
  cavity_.assign(samples.size(), 0.0);
  for (size_t q = 0; q < samples.size(); ++q) {
    if (!samples[q].spot) continue;
    cavitated_[q] = 1;
    cavity_[q] = samples[q].film;
  }
  tally(samples);
}

void CavitatingFilm::update(const std::vector<FilmSample>& samples, double dt) {
  cavitated_.resize(samples.size(), 0);
  cavity_.resize(samples.size(), 0.0);
  for (size_t q = 0; q < samples.size(); ++q) {
    if (cavitated_[q] != 0) {
      cavity_[q] += dt * samples[q].opening_rate;
      if (cavity_[q] <= kClosedCavityThickness) cavitated_[q] = 0, cavity_[q] = 0.0;  // the liquid is back at the wall
    } else if (samples[q].normal_stress > -p_c_) {
      cavitated_[q] = 1;  // the liquid pulls: the cavity opens from the next step on
      cavity_[q] = 0.0;
    }
  }
  tally(samples);
}

void CavitatingFilm::tally(const std::vector<FilmSample>& samples) {
  cavity_area_ = 0.0;
  double length = 0.0, cavitated_length = 0.0;
  for (size_t q = 0; q < samples.size(); ++q) {
    length += samples[q].length;
    if (cavitated_[q] == 0) continue;
    cavity_area_ += cavity_[q] * samples[q].length;
    cavitated_length += samples[q].length;
  }
  cavitated_fraction_ = length > 0.0 ? cavitated_length / length : 0.0;
}

}  // namespace mufric::coupling
