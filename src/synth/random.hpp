#pragma once
// Deterministic randomness for the synthetic scene: SplitMix64 mixing, so a seed gives the same
// layout, textures and sample jitter on every platform (the standard distributions do not).
#include <cstdint>

namespace iesrgs::synth {

// SplitMix64's output function: a bijective mix with full avalanche.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A hash of a 2D lattice cell (or any pair of integers) under a seed.
inline uint64_t hash_cell(int64_t x, int64_t y, uint64_t seed) {
  constexpr uint64_t kGolden = 0x9e3779b97f4a7c15ULL;
  return mix64(seed + kGolden * mix64(uint64_t(x) + kGolden * mix64(uint64_t(y) + kGolden)));
}

// Uniform in [0, 1) from the top 53 bits.
inline double unit_interval(uint64_t bits) {
  return double(bits >> 11) * 0x1.0p-53;
}

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}

  uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit_interval(next()); }
  // Uniform in [0, n).
  int below(int n) { return int(next() % uint64_t(n)); }

 private:
  uint64_t state_;
};

}  // namespace iesrgs::synth
