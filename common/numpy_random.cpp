#include "common/numpy_random.hpp"

#include <cmath>

namespace mufric {
namespace {

// SeedSequence's hash constants (O'Neill's seed_seq_fe, as numpy/random/bit_generator.pyx uses them).
constexpr std::uint32_t kInitA = 0x43b0d7e5u, kMultA = 0x931e8875u, kInitB = 0x8b51f9ddu, kMultB = 0x58f38dedu;
constexpr std::uint32_t kMixMultL = 0xca01f9ddu, kMixMultR = 0x4973f715u;
constexpr int kXShift = 16;
constexpr int kPoolSize = 4;

std::uint32_t hashmix(std::uint32_t value, std::uint32_t& hash_const) {
  value ^= hash_const;
  hash_const *= kMultA;
  value *= hash_const;
  return value ^ (value >> kXShift);
}

std::uint32_t mix(std::uint32_t x, std::uint32_t y) {
  std::uint32_t result = kMixMultL * x - kMixMultR * y;
  return result ^ (result >> kXShift);
}

// SeedSequence(seed).generate_state(4, uint64) for a one-word entropy.
std::array<std::uint64_t, 4> seed_sequence_state(std::uint32_t seed) {
  std::array<std::uint32_t, kPoolSize> pool{};
  std::uint32_t hash_const = kInitA;
  for (int i = 0; i < kPoolSize; ++i) pool[i] = hashmix(i == 0 ? seed : 0u, hash_const);
  for (int source = 0; source < kPoolSize; ++source)
    for (int target = 0; target < kPoolSize; ++target)
      if (source != target) pool[target] = mix(pool[target], hashmix(pool[source], hash_const));
  std::array<std::uint32_t, 8> words{};
  hash_const = kInitB;
  for (int i = 0; i < 8; ++i) {
    std::uint32_t value = pool[i % kPoolSize] ^ hash_const;
    hash_const *= kMultB;
    value *= hash_const;
    words[i] = value ^ (value >> kXShift);
  }
  std::array<std::uint64_t, 4> state{};  // little-endian pairs of 32-bit words
  for (int i = 0; i < 4; ++i) state[i] = std::uint64_t{words[2 * i]} | (std::uint64_t{words[2 * i + 1]} << 32);
  return state;
}

// PCG's 128-bit LCG multiplier (O'Neill 2014, pcg_variants.h PCG_DEFAULT_MULTIPLIER_128).
constexpr NumpyRandomWord kPcgMultiplier =
    (static_cast<NumpyRandomWord>(2549297995355413924ull) << 64) | 4865540595714422341ull;

// The ziggurat of Marsaglia & Tsang (2000, J. Stat. Softw. 5(8)) with 256 layers, laid out as NumPy's
// tables (ki, wi, fi; layer 0 the base with the tail): x_i from the recursion x_{i-1} =
// f^{-1}(v / x_i + f(x_i)), f(x) = exp(-x²/2), from x_255 = r, computed in long double; v is each
// layer's area, that of the base with its tail: r f(r) + √(π/2) erfc(r/√2).
constexpr long double kZigguratR = 3.6541528853610087963519472518L;
constexpr double kTwoTo52 = 4503599627370496.0;

struct Ziggurat {
  std::array<std::uint64_t, 256> ki{};
  std::array<double, 256> wi{}, fi{};
  Ziggurat() {
    std::array<long double, 256> x{};
    auto f = [](long double v) { return std::exp(-0.5L * v * v); };
    const long double kZigguratArea =
        kZigguratR * f(kZigguratR) + std::sqrt(std::acos(-1.0L) / 2.0L) * std::erfc(kZigguratR / std::sqrt(2.0L));
    x[255] = kZigguratR;
    for (int i = 255; i > 1; --i) x[i - 1] = std::sqrt(-2.0L * std::log(kZigguratArea / x[i] + f(x[i])));
    x[0] = 0.0L;
    const long double base_width = kZigguratArea / f(kZigguratR);  // the base layer's equivalent width
    ki[0] = static_cast<std::uint64_t>(kTwoTo52 * (kZigguratR / base_width));
    wi[0] = static_cast<double>(base_width / kTwoTo52);
    fi[0] = 1.0;
    for (int i = 1; i < 256; ++i) {
      ki[i] = static_cast<std::uint64_t>(kTwoTo52 * (x[i - 1] / x[i]));
      wi[i] = static_cast<double>(x[i] / kTwoTo52);
      fi[i] = static_cast<double>(f(x[i]));
    }
  }
};

const Ziggurat& ziggurat() {
  static const Ziggurat tables;
  return tables;
}

}  // namespace

NumpyRandom::NumpyRandom(std::uint32_t seed) {
  const auto words = seed_sequence_state(seed);
  const NumpyRandomWord initial_state = (static_cast<NumpyRandomWord>(words[0]) << 64) | words[1];
  const NumpyRandomWord sequence = (static_cast<NumpyRandomWord>(words[2]) << 64) | words[3];
  // pcg_setseq_128_srandom_r
  increment_ = (sequence << 1u) | 1u;
  state_ = 0;
  state_ = state_ * kPcgMultiplier + increment_;
  state_ += initial_state;
  state_ = state_ * kPcgMultiplier + increment_;
}

std::uint64_t NumpyRandom::next_uint64() {
  // PCG XSL-RR 128/64 (O'Neill 2014): step, then output of the new state.
  state_ = state_ * kPcgMultiplier + increment_;
  const auto folded = static_cast<std::uint64_t>(state_ >> 64) ^ static_cast<std::uint64_t>(state_);
  const auto rotation = static_cast<unsigned>(state_ >> 122);
  return (folded >> rotation) | (folded << ((64u - rotation) & 63u));
}

double NumpyRandom::next_double() { return static_cast<double>(next_uint64() >> 11) * (1.0 / 9007199254740992.0); }

double NumpyRandom::uniform(double low, double high) { return low + (high - low) * next_double(); }

double NumpyRandom::standard_normal() {
  const Ziggurat& z = ziggurat();
  const double r = static_cast<double>(kZigguratR), inverse_r = static_cast<double>(1.0L / kZigguratR);
  for (;;) {
    std::uint64_t bits = next_uint64();
    const int layer = static_cast<int>(bits & 0xff);
    bits >>= 8;
    const bool negative = bits & 0x1;
    const std::uint64_t magnitude = (bits >> 1) & 0x000fffffffffffffull;
    double x = static_cast<double>(magnitude) * z.wi[layer];
    if (negative) x = -x;
    if (magnitude < z.ki[layer]) return x;
    if (layer == 0) {
      for (;;) {  // the tail beyond r (Marsaglia 1964), with 1 - U as NumPy does against log(0)
        const double xx = -inverse_r * std::log1p(-next_double());
        const double yy = -std::log1p(-next_double());
        if (yy + yy > xx * xx) return ((magnitude >> 8) & 0x1) ? -(r + xx) : r + xx;
      }
    }
    if ((z.fi[layer - 1] - z.fi[layer]) * next_double() + z.fi[layer] < std::exp(-0.5 * x * x)) return x;
  }
}

}  // namespace mufric
