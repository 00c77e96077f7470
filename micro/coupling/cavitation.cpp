#include "micro/coupling/cavitation.hpp"

#include <algorithm>

#include "common/error.hpp"

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

std::vector<char> wetted_spots(const std::vector<FilmSample>& samples, const std::vector<char>& liquid_at_wall) {
  const size_t n = samples.size();
  if (liquid_at_wall.size() != n) throw Error("wetted spots: one liquid flag per film sample is needed");
  std::vector<char> wetted(n, 0);
  const auto pocket_with_liquid = [&](size_t q) { return !samples[q].spot && liquid_at_wall[q] != 0; };
  for (size_t start = 0; start < n; ++start) {
    // A spot run starts where the sample before it (periodically) is a pocket sample.
    const size_t before = (start + n - 1) % n;
    if (!samples[start].spot || samples[before].spot) continue;
    size_t end = start;  // the run's last sample
    while (samples[(end + 1) % n].spot) end = (end + 1) % n;
    const size_t after = (end + 1) % n;
    if (!pocket_with_liquid(before) && !pocket_with_liquid(after)) continue;
    for (size_t q = start;; q = (q + 1) % n) {
      wetted[q] = 1;
      if (q == end) break;
    }
  }
  return wetted;
}

void CavitatingFilm::form(const std::vector<FilmSample>& samples) {
  cavitated_.assign(samples.size(), 0);
  cavity_.assign(samples.size(), 0.0);
  for (size_t q = 0; q < samples.size(); ++q) {
    if (!samples[q].spot) continue;
    cavitated_[q] = 1;
    cavity_[q] = samples[q].film * samples[q].width;  // the layer's area (its thickness is across x)
  }
  tally(samples);
}

void CavitatingFilm::update(const std::vector<FilmSample>& samples, double dt) {
  const size_t n = samples.size();
  cavitated_.resize(n, 0);
  cavity_.resize(n, 0.0);
  std::vector<double> overshoot(n, 0.0);
  overgrowth_ = 0.0;
  for (size_t q = 0; q < n; ++q) {
    if (cavitated_[q] != 0) {
      cavity_[q] += dt * samples[q].opening_rate * samples[q].wall_length;
      const double gap = samples[q].film * samples[q].width;
      if (within_gap_ && cavity_[q] > gap) overgrowth_ += cavity_[q] - gap, cavity_[q] = gap;
      if (cavity_[q] <= kClosedCavityThickness * samples[q].wall_length) {  // the liquid is back at the wall
        overshoot[q] = std::max(0.0, -cavity_[q]);
        cavitated_[q] = 0, cavity_[q] = 0.0;
      }
    } else if (samples[q].normal_stress > -p_c_) {
      cavitated_[q] = 1;  // the liquid pulls: the cavity opens from the next step on
      cavity_[q] = 0.0;
    }
  }
  // The liquid that ran past the wall where a cavity closed fills the nearest cavities, nearer first.
  closing_overshoot_ = lost_overshoot_ = 0.0;
  for (size_t q = 0; q < n; ++q) {
    double excess = overshoot[q];
    closing_overshoot_ += excess;
    for (size_t d = 1; excess > 0.0 && d <= n / 2; ++d) {
      for (const size_t r : {(q + n - d) % n, (q + d) % n}) {
        if (cavitated_[r] == 0 || cavity_[r] <= 0.0) continue;
        const double taken = std::min(cavity_[r], excess);
        cavity_[r] -= taken;
        excess -= taken;
        if (cavity_[r] <= kClosedCavityThickness * samples[r].wall_length) cavitated_[r] = 0, cavity_[r] = 0.0;
        if (excess <= 0.0) break;
      }
    }
    lost_overshoot_ += excess;
  }
  tally(samples);
}

void CavitatingFilm::tally(const std::vector<FilmSample>& samples) {
  cavity_area_ = 0.0;
  double length = 0.0, cavitated_length = 0.0;
  for (size_t q = 0; q < samples.size(); ++q) {
    length += samples[q].wall_length;
    if (cavitated_[q] == 0) continue;
    cavity_area_ += cavity_[q];
    cavitated_length += samples[q].wall_length;
  }
  cavitated_fraction_ = length > 0.0 ? cavitated_length / length : 0.0;
}

}  // namespace mufric::coupling
