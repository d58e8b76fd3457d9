// SPDX-License-Identifier: Apache-2.0
#pragma once
// Counter-based random numbers: every draw is a pure function of (seed, stream, index), so results do not
// depend on thread scheduling. A stream is e.g. one pixel sample of a render; `dimension` counts the
// draws within it.

#include <cstdint>

namespace ct {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

class Random {
 public:
  Random(std::uint64_t seed, std::uint64_t stream) : state_(mix64(seed ^ mix64(stream))) {}
  std::uint64_t next_u64() { return mix64(state_ += 0x9E3779B97F4A7C15ull); }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

}  // namespace ct
