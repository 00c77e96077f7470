#pragma once
// NumPy's default random stream in C++: numpy.random.default_rng(seed) (SeedSequence → PCG64) and
// its standard_normal and uniform, draw for draw. A Monte Carlo analysis written first in Python
// (data/cirp2022_ti6al4v_tin/rake_face.py, now surrogate/reduction) gives the same numbers here, and a
// user can reproduce ours with NumPy.
#include <array>
#include <cstdint>

namespace mufric {

// PCG64's 128-bit state (a GCC and Clang extension, as NumPy's own C uses).
__extension__ typedef unsigned __int128 NumpyRandomWord;

class NumpyRandom {
 public:
  // As numpy.random.default_rng(seed) for a non-negative integer seed below 2^32.
  explicit NumpyRandom(std::uint32_t seed);

  std::uint64_t next_uint64();
  // Generator.random(): [0, 1) with 53 bits.
  double next_double();
  // Generator.standard_normal(): NumPy's 256-layer ziggurat (random_standard_normal).
  double standard_normal();
  // Generator.uniform(low, high) = low + (high - low) · random().
  double uniform(double low, double high);

 private:
  NumpyRandomWord state_ = 0, increment_ = 0;
};

}  // namespace mufric
