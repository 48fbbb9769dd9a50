#include "fvs/synthetic/material.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "fvs/synthetic/noise.h"
#include "fvs/synthetic/random.h"

namespace fvs::synthetic {
namespace {

double SmoothStep(double a, double b, double x) {
  const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// HSV (all in [0, 1]) to linear RGB.
Eigen::Vector3d HsvToRgb(double h, double s, double v) {
  h = (h - std::floor(h)) * 6.0;
  const int i = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (i) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

Eigen::Vector3d RandomColor(SceneRandom* random, double value_lo, double value_hi) {
  const double lo[3] = {0.0, 0.25, value_lo}, hi[3] = {1.0, 0.95, value_hi};
  double hsv[3];
  random->Uniform3(lo, hi, hsv);
  return HsvToRgb(hsv[0], hsv[1], hsv[2]);
}

// A colour chosen by a hash: patches and spots get colours of their own.
Eigen::Vector3d HashColor(uint64_t h) {
  return HsvToRgb(HashToUnit(Mix64(h ^ 11)), 0.3 + 0.65 * HashToUnit(Mix64(h ^ 12)),
                  0.2 + 0.8 * HashToUnit(Mix64(h ^ 13)));
}

}  // namespace

Eigen::Vector3d ProceduralMaterial::Albedo(const Eigen::Vector3d& world_point) const {
  const Eigen::Vector3d q = rotation * world_point + offset;

  // Low-frequency colour field between two palette colours.
  const double field = FractalNoise(q * base_frequency, 4, seed);
  Eigen::Vector3d color =
      palette[0] + (palette[1] - palette[0]) * SmoothStep(0.3, 0.7, field);

  // Structured pattern: gives corners and blobs of well-defined scale.
  const Eigen::Vector3d pq = q * pattern_frequency;
  Eigen::Vector3d pattern_color = color;
  switch (pattern) {
    case MaterialPattern::kPatches: {
      const CellularSample c = CellularNoise(pq, HashCombine(seed, 101));
      pattern_color = 0.5 * (HashColor(c.cell_hash) + palette[2]);
      // Dark seams between cells: strong corners where three cells meet.
      pattern_color *= 0.25 + 0.75 * SmoothStep(0.04, 0.12, c.f2 - c.f1);
      break;
    }
    case MaterialPattern::kChecker: {
      // Warping the lattice by noise keeps the checker from being a repeated pattern that
      // would confuse matching.
      const Eigen::Vector3d w(FractalNoise(pq * 0.5, 2, seed + 1),
                              FractalNoise(pq * 0.5, 2, seed + 2),
                              FractalNoise(pq * 0.5, 2, seed + 3));
      const Eigen::Vector3d cq = pq + 1.2 * w;
      const int parity = (static_cast<int64_t>(std::floor(cq.x())) +
                          static_cast<int64_t>(std::floor(cq.y())) +
                          static_cast<int64_t>(std::floor(cq.z()))) &
                         1;
      pattern_color = parity ? palette[2] : palette[3];
      break;
    }
    case MaterialPattern::kStripes: {
      const double phase =
          pq.x() * 6.2831853 + 5.0 * FractalNoise(pq * 0.35, 3, seed + 4);
      const double s = 0.5 + 0.5 * std::sin(phase);
      pattern_color = palette[2] + (palette[3] - palette[2]) * SmoothStep(0.35, 0.65, s);
      break;
    }
    case MaterialPattern::kSpots: {
      const CellularSample c = CellularNoise(pq, HashCombine(seed, 202));
      const double radius = 0.18 + 0.22 * HashToUnit(Mix64(c.cell_hash ^ 21));
      const double inside = 1.0 - SmoothStep(radius - 0.04, radius + 0.04, c.f1);
      pattern_color = color + (HashColor(c.cell_hash) - color) * inside;
      break;
    }
  }
  color += (pattern_color - color) * pattern_strength;

  // Mid-scale mottling and fine grain: texture at 5-20 px even inside the large patches
  // of the nearest surfaces, where SIFT would otherwise find flat areas.
  const double mottle = FractalNoise(q * (3.0 * pattern_frequency), 2, seed + 6);
  const double grain = FractalNoise(q * grain_frequency, 2, seed + 5);
  color *= (1.0 + 0.6 * grain_strength * (2.0 * mottle - 1.0)) *
           (1.0 + grain_strength * (2.0 * grain - 1.0));
  return color.cwiseMax(0.0).cwiseMin(1.0);
}

ProceduralMaterial RandomMaterial(SceneRandom* random, double scale) {
  ProceduralMaterial m;
  m.seed = random->Next();
  const double axis_lo[3] = {-1, -1, -1}, axis_hi[3] = {1, 1, 1};
  double axis[3];
  random->Uniform3(axis_lo, axis_hi, axis);
  const double angle = random->Uniform(0, 6.2831853);
  // + 1e-3 in z: never a zero axis.
  m.rotation = Eigen::AngleAxisd(
                   angle, Eigen::Vector3d(axis[0], axis[1], axis[2] + 1e-3).normalized())
                   .toRotationMatrix();
  const double offset_lo[3] = {-100, -100, -100}, offset_hi[3] = {100, 100, 100};
  double offset[3];
  random->Uniform3(offset_lo, offset_hi, offset);
  m.offset = Eigen::Vector3d(offset[0], offset[1], offset[2]);
  m.palette[0] = RandomColor(random, 0.15, 0.55);
  m.palette[1] = RandomColor(random, 0.55, 1.0);
  m.palette[2] = RandomColor(random, 0.1, 1.0);
  m.palette[3] = RandomColor(random, 0.1, 1.0);
  // Make sure the two pattern colours differ in brightness (SIFT works on grey).
  if (std::abs(m.palette[2].sum() - m.palette[3].sum()) < 0.6) {
    if (m.palette[2].sum() > 1.5) {
      m.palette[3] = m.palette[3] * 0.3;
    } else {
      m.palette[3] = (m.palette[3] + Eigen::Vector3d::Constant(0.6)).cwiseMin(1.0);
    }
  }
  m.base_frequency = random->Uniform(0.8, 2.5) / scale;
  m.pattern =
      static_cast<MaterialPattern>(random->UniformInt(0, kNumMaterialPatterns - 1));
  m.pattern_frequency = random->Uniform(3.0, 8.0) / scale;
  m.pattern_strength = random->Uniform(0.55, 0.9);
  m.grain_frequency = random->Uniform(25.0, 45.0) / std::sqrt(scale);
  m.grain_strength = random->Uniform(0.3, 0.45);
  return m;
}

}  // namespace fvs::synthetic
