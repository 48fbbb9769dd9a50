// Solid (3D) noise functions for procedural textures: value noise, fractal sums of it and
// cellular (Worley) noise. All are pure functions of the point and a seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace fvs::synthetic {

// Smoothly interpolated lattice noise in [0, 1], lattice spacing 1.
double ValueNoise(const Eigen::Vector3d& p, uint64_t seed);

// Sum of `octaves` octaves of value noise (frequency x2, amplitude x0.5 per octave),
// normalised to [0, 1].
double FractalNoise(const Eigen::Vector3d& p, int octaves, uint64_t seed);

struct CellularSample {
  double f1 = 0;           // distance to the nearest feature point
  double f2 = 0;           // distance to the second nearest
  uint64_t cell_hash = 0;  // identifies the nearest feature point's cell
};

// One jittered feature point per unit cell; distances in lattice units.
CellularSample CellularNoise(const Eigen::Vector3d& p, uint64_t seed);

}  // namespace fvs::synthetic
