// Procedural solid materials: the albedo is a function of the 3D world point, so a
// surface needs no texture coordinates and every surface of the scene, at every distance
// the camera path gives, carries detail at the scales SIFT detects (blobs and corners of
// 2-40 px at 640x480). Each material mixes a low-frequency colour field (fractal value
// noise), one structured pattern (coloured Voronoi patches with dark seams, a
// noise-warped checker, wobbly stripes, or spots) and fine grain; a random rotation and
// offset per material make sure no two surfaces look alike.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

namespace fvs::synthetic {

class SceneRandom;

enum class MaterialPattern { kPatches = 0, kChecker, kStripes, kSpots };
constexpr int kNumMaterialPatterns = 4;

struct ProceduralMaterial {
  uint64_t seed = 0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // world -> texture frame
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector3d, 4> palette;  // linear RGB in [0, 1]
  double base_frequency = 2.0;             // cycles per metre of the colour field
  MaterialPattern pattern = MaterialPattern::kPatches;
  double pattern_frequency = 5.0;  // cells (or stripes) per metre
  double pattern_strength = 0.7;   // 0: none, 1: pattern only
  double grain_frequency = 40.0;
  double grain_strength = 0.25;

  // Linear RGB albedo in [0, 1] at a world point.
  Eigen::Vector3d Albedo(const Eigen::Vector3d& world_point) const;
};

// A random material; `scale` > 1 makes the pattern coarser (large surfaces seen from
// far).
ProceduralMaterial RandomMaterial(SceneRandom* random, double scale = 1.0);

}  // namespace fvs::synthetic
