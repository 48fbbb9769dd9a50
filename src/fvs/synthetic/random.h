// Deterministic randomness for the synthetic scene generator.
// std::uniform_real_distribution and friends may differ between standard libraries, so
// only the raw std::mt19937_64 stream (fixed by the standard) is used and every
// distribution is implemented here. Texture noise uses stateless integer hashing of
// lattice coordinates (splitmix64), so evaluation order and thread count cannot change a
// pixel.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace fvs::synthetic {

// splitmix64 finaliser: a good 64-bit mixer.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline uint64_t HashCombine(uint64_t seed, uint64_t value) {
  return Mix64(seed ^ Mix64(value));
}

// Uniform in [0, 1) from the top 53 bits.
inline double HashToUnit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

class SceneRandom {
 public:
  explicit SceneRandom(uint64_t seed) : engine_(seed) {}

  uint64_t Next() { return engine_(); }
  // Uniform in [0, 1).
  double Uniform() { return HashToUnit(engine_()); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [lo, hi] (the modulo bias is irrelevant for these small ranges).
  int UniformInt(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<uint64_t>(hi - lo + 1));
  }
  // Symmetric in [-amplitude, amplitude).
  double Symmetric(double amplitude) { return amplitude * (2.0 * Uniform() - 1.0); }
  // Three draws in a fixed order. Function arguments are evaluated in an unspecified
  // order (GCC and Clang differ), so no expression here ever draws more than once.
  void Uniform3(const double lo[3], const double hi[3], double out[3]) {
    for (int i = 0; i < 3; ++i) out[i] = Uniform(lo[i], hi[i]);
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace fvs::synthetic
