#include "fvs/synthetic/noise.h"

#include <cmath>
#include <limits>

#include "fvs/synthetic/random.h"

namespace fvs::synthetic {
namespace {

// One multiply per coordinate and a single mix: lattice hashing dominates texture cost.
uint64_t LatticeHash(int64_t x, int64_t y, int64_t z, uint64_t seed) {
  return Mix64(seed ^ (static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull) ^
               (static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full) ^
               (static_cast<uint64_t>(z) * 0x165667B19E3779F9ull));
}

double Fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

double Lerp(double a, double b, double t) { return a + (b - a) * t; }

}  // namespace

double ValueNoise(const Eigen::Vector3d& p, uint64_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const int64_t x0 = static_cast<int64_t>(fx), y0 = static_cast<int64_t>(fy),
                z0 = static_cast<int64_t>(fz);
  const double tx = Fade(p.x() - fx), ty = Fade(p.y() - fy), tz = Fade(p.z() - fz);
  double c[2][2][2];
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        c[dz][dy][dx] = HashToUnit(LatticeHash(x0 + dx, y0 + dy, z0 + dz, seed));
      }
    }
  }
  const double y00 = Lerp(c[0][0][0], c[0][0][1], tx);
  const double y01 = Lerp(c[0][1][0], c[0][1][1], tx);
  const double y10 = Lerp(c[1][0][0], c[1][0][1], tx);
  const double y11 = Lerp(c[1][1][0], c[1][1][1], tx);
  return Lerp(Lerp(y00, y01, ty), Lerp(y10, y11, ty), tz);
}

double FractalNoise(const Eigen::Vector3d& p, int octaves, uint64_t seed) {
  double sum = 0, norm = 0, amplitude = 1, frequency = 1;
  for (int o = 0; o < octaves; ++o) {
    // Offsetting each octave keeps lattice points of different octaves from lining up.
    const Eigen::Vector3d shift(17.31 * o, -9.77 * o, 5.13 * o);
    sum += amplitude * ValueNoise(p * frequency + shift, HashCombine(seed, o));
    norm += amplitude;
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return norm > 0 ? sum / norm : 0.5;
}

CellularSample CellularNoise(const Eigen::Vector3d& p, uint64_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const int64_t x0 = static_cast<int64_t>(fx), y0 = static_cast<int64_t>(fy),
                z0 = static_cast<int64_t>(fz);
  double best1 = std::numeric_limits<double>::max(), best2 = best1;
  uint64_t best_hash = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const uint64_t h = LatticeHash(x0 + dx, y0 + dy, z0 + dz, seed);
        // Three 21-bit jitters from one hash.
        constexpr double kScale = 1.0 / (1 << 21);
        const Eigen::Vector3d feature(fx + dx + kScale * (h & 0x1FFFFF),
                                      fy + dy + kScale * ((h >> 21) & 0x1FFFFF),
                                      fz + dz + kScale * ((h >> 42) & 0x1FFFFF));
        const double d2 = (feature - p).squaredNorm();
        if (d2 < best1) {
          best2 = best1;
          best1 = d2;
          best_hash = h;
        } else if (d2 < best2) {
          best2 = d2;
        }
      }
    }
  }
  return {std::sqrt(best1), std::sqrt(best2), best_hash};
}

}  // namespace fvs::synthetic
