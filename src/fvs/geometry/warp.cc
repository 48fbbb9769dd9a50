#include "fvs/geometry/warp.h"

#include <algorithm>
#include <cmath>

#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {

void WarpOptions::Check() const {
  Require(occlusion_tolerance > 0 && std::isfinite(occlusion_tolerance), "warp options",
          "occlusion_tolerance must be positive");
  Require(invalid_depth > 0 && std::isfinite(invalid_depth), "warp options",
          "invalid_depth must be positive");
}

double EffectiveDepth(float depth, double invalid_depth) {
  return (depth > 0 && std::isfinite(depth)) ? static_cast<double>(depth) : invalid_depth;
}

bool SourceSeesDepth(const Image& source_depth, double u, double v, double z,
                     double tolerance, double invalid_depth) {
  const int w = source_depth.width, h = source_depth.height;
  const int sx = std::min(static_cast<int>(u), w - 1);
  const int sy = std::min(static_cast<int>(v), h - 1);
  if (std::abs(z - EffectiveDepth(source_depth.at(sx, sy), invalid_depth)) <=
      tolerance * z) {
    return true;
  }
  // Bilinear between the 4 nearest pixel centres, only where all 4 are surface.
  const double fx = std::clamp(u - 0.5, 0.0, w - 1.0),
               fy = std::clamp(v - 0.5, 0.0, h - 1.0);
  const int x0 = std::min(static_cast<int>(fx), std::max(w - 2, 0));
  const int y0 = std::min(static_cast<int>(fy), std::max(h - 2, 0));
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double ax = fx - x0, ay = fy - y0;
  const float d00 = source_depth.at(x0, y0), d10 = source_depth.at(x1, y0);
  const float d01 = source_depth.at(x0, y1), d11 = source_depth.at(x1, y1);
  for (float d : {d00, d10, d01, d11}) {
    if (!(d > 0 && std::isfinite(d))) return false;
  }
  const double bilinear =
      (1 - ay) * ((1 - ax) * d00 + ax * d10) + ay * ((1 - ax) * d01 + ax * d11);
  return std::abs(z - bilinear) <= tolerance * z;
}

namespace {

// Where a point (or, at infinity, a direction) in the source camera frame lands in the
// source image.
struct SourceHit {
  // (-1, -1, 0) unless it projects (in front of the source, finite).
  double u = -1, v = -1, z = 0;
  bool inside = false;  // it projects inside the source image
};

SourceHit ProjectIntoSource(const PinholeCamera& source, const Eigen::Vector3d& X) {
  SourceHit hit;
  // Z relative to the scale of the point: a point behind or at the source centre has no
  // projection.
  if (!(X.z() > 1e-12 * std::max(1.0, X.norm()))) return hit;
  const double u = source.fx * X.x() / X.z() + source.cx;
  const double v = source.fy * X.y() / X.z() + source.cy;
  if (!(std::isfinite(u) && std::isfinite(v))) return hit;
  hit.u = u;
  hit.v = v;
  hit.z = X.z();
  hit.inside = u >= 0 && v >= 0 && u < source.width && v < source.height;
  return hit;
}

// One target pixel's ray (x, y, 1) in the target frame and its depth (0 = no surface).
struct TargetRay {
  Eigen::Vector3d ray;
  double depth = 0;
};

// Writes pixel i of the map; returns whether the source sees it.
bool WarpPixel(const TargetRay& pixel, const Eigen::Matrix3d& R_rel,
               const Eigen::Vector3d& t_rel, const PinholeCamera& source,
               const Image& source_depth, const WarpOptions& options, size_t i,
               WarpMap* map) {
  const bool surface = pixel.depth > 0;
  if (!surface && !options.at_infinity) {
    map->source_xy.data[2 * i] = map->source_xy.data[2 * i + 1] = -1.f;
    map->source_z.data[i] = map->valid_depth.data[i] = map->valid_warp.data[i] = 0.f;
    return false;
  }
  // At infinity only the direction counts: the rotation alone, no translation, and no
  // huge stand-in depth whose source Z would never match a stand-in source depth.
  const Eigen::Vector3d X =
      surface ? Eigen::Vector3d(R_rel * (pixel.depth * pixel.ray) + t_rel)
              : Eigen::Vector3d(R_rel * pixel.ray);
  const SourceHit hit = ProjectIntoSource(source, X);
  bool seen = false;
  if (hit.inside) {
    seen = surface ? SourceSeesDepth(source_depth, hit.u, hit.v, hit.z,
                                     options.occlusion_tolerance, options.invalid_depth)
                   : SourceSeesInfinity(source_depth, hit.u, hit.v);
  }
  // Keep far-off coordinates finite in float and clearly outside.
  const double lim = 1e7 + 4.0 * std::max(source.width, source.height);
  map->source_xy.data[2 * i] = static_cast<float>(std::clamp(hit.u, -lim, lim));
  map->source_xy.data[2 * i + 1] = static_cast<float>(std::clamp(hit.v, -lim, lim));
  map->source_z.data[i] = surface ? static_cast<float>(std::min(hit.z, 1e30)) : 0.f;
  map->valid_depth.data[i] = surface ? 1.f : 0.f;
  map->valid_warp.data[i] = seen ? 1.f : 0.f;
  return seen;
}

void CheckWarpInputs(const PinholeCamera& target, const Image& target_depth,
                     const PinholeCamera& source, const Image& source_depth,
                     const WarpOptions& options) {
  options.Check();
  Require(target.IsValid(), "warp", "invalid target camera");
  Require(source.IsValid(), "warp", "invalid source camera");
  Require(target_depth.width == target.width && target_depth.height == target.height &&
              target_depth.channels == 1,
          "warp", "target depth size does not match the target camera");
  Require(source_depth.width == source.width && source_depth.height == source.height &&
              source_depth.channels == 1,
          "warp", "source depth size does not match the source camera");
}

}  // namespace

bool SourceSeesInfinity(const Image& source_depth, double u, double v) {
  const int sx = std::min(static_cast<int>(u), source_depth.width - 1);
  const int sy = std::min(static_cast<int>(v), source_depth.height - 1);
  const float d = source_depth.at(sx, sy);
  return !(d > 0 && std::isfinite(d));
}

WarpMap ComputeWarpMap(const PinholeCamera& target, const Image& target_depth,
                       const PinholeCamera& source, const Image& source_depth,
                       const WarpOptions& options) {
  CheckWarpInputs(target, target_depth, source, source_depth, options);
  const int w = target.width, h = target.height;
  WarpMap map;
  map.source_xy = Image(w, h, 2);
  map.valid_depth = Image(w, h, 1);
  map.valid_warp = Image(w, h, 1);
  map.source_z = Image(w, h, 1);

  // Relative pose target camera -> source camera, once, in double.
  const Eigen::Matrix3d R_rel = source.R * target.R.transpose();
  const Eigen::Vector3d t_rel = source.t - R_rel * target.t;
  std::vector<int64_t> valid_per_row(h, 0);
  ParallelFor(
      0, h,
      [&](int64_t y) {
        int64_t valid_count = 0;
        TargetRay pixel;
        pixel.ray.y() = (y + 0.5 - target.cy) / target.fy;
        pixel.ray.z() = 1.0;
        for (int x = 0; x < w; ++x) {
          const float raw = target_depth.at(x, static_cast<int>(y));
          pixel.depth = raw > 0 && std::isfinite(raw) ? raw : 0.0;
          pixel.ray.x() = (x + 0.5 - target.cx) / target.fx;
          const size_t i = static_cast<size_t>(y) * w + x;
          valid_count +=
              WarpPixel(pixel, R_rel, t_rel, source, source_depth, options, i, &map);
        }
        valid_per_row[y] = valid_count;
      },
      options.num_threads);
  for (int64_t c : valid_per_row) map.num_valid += c;
  return map;
}

Image GridSampleCoordinates(const WarpMap& map, int source_width, int source_height) {
  Image grid(map.source_xy.width, map.source_xy.height, 2);
  for (size_t i = 0; i + 1 < grid.data.size(); i += 2) {
    grid.data[i] = static_cast<float>(2.0 * map.source_xy.data[i] / source_width - 1.0);
    grid.data[i + 1] =
        static_cast<float>(2.0 * map.source_xy.data[i + 1] / source_height - 1.0);
  }
  return grid;
}

void SampleBilinear(const Image& image, double u, double v, float* out,
                    bool clamp_to_border) {
  const int c = image.channels;
  for (int k = 0; k < c; ++k) out[k] = 0.f;
  // Pixel centres at +0.5: continuous index = u - 0.5.
  double fx = u - 0.5, fy = v - 0.5;
  if (clamp_to_border) {
    if (!(std::isfinite(fx) && std::isfinite(fy)) || image.empty()) return;
    fx = std::clamp(fx, 0.0, image.width - 1.0);
    fy = std::clamp(fy, 0.0, image.height - 1.0);
  }
  if (!(fx > -1.0 && fy > -1.0 && fx < image.width && fy < image.height)) return;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const float ax = static_cast<float>(fx - x0), ay = static_cast<float>(fy - y0);
  const float wts[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  const int xs[4] = {x0, x0 + 1, x0, x0 + 1};
  const int ys[4] = {y0, y0, y0 + 1, y0 + 1};
  for (int n = 0; n < 4; ++n) {
    if (xs[n] < 0 || ys[n] < 0 || xs[n] >= image.width || ys[n] >= image.height) continue;
    const float* p = image.data.data() + image.Index(xs[n], ys[n]);
    for (int k = 0; k < c; ++k) out[k] += wts[n] * p[k];
  }
}

void SampleBicubic(const Image& image, double u, double v, float* out) {
  const int c = image.channels;
  for (int k = 0; k < c; ++k) out[k] = 0.f;
  double fx = u - 0.5, fy = v - 0.5;  // continuous index, pixel centres at integers
  if (!(std::isfinite(fx) && std::isfinite(fy)) || image.empty()) return;
  fx = std::clamp(fx, 0.0, image.width - 1.0);
  fy = std::clamp(fy, 0.0, image.height - 1.0);
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  // Catmull-Rom weights of the centres at offsets -1, 0, 1, 2 from x0 (they sum to 1).
  const auto weights = [](double t, float* w) {
    w[0] = static_cast<float>(((-0.5 * t + 1.0) * t - 0.5) * t);
    w[1] = static_cast<float>((1.5 * t - 2.5) * t * t + 1.0);
    w[2] = static_cast<float>(((-1.5 * t + 2.0) * t + 0.5) * t);
    w[3] = static_cast<float>((0.5 * t - 0.5) * t * t);
  };
  float wx[4], wy[4];
  weights(fx - x0, wx);
  weights(fy - y0, wy);
  int xs[4];
  for (int n = 0; n < 4; ++n) xs[n] = std::clamp(x0 - 1 + n, 0, image.width - 1);
  for (int m = 0; m < 4; ++m) {
    const int y = std::clamp(y0 - 1 + m, 0, image.height - 1);
    for (int n = 0; n < 4; ++n) {
      const float weight = wy[m] * wx[n];
      const float* p = image.data.data() + image.Index(xs[n], y);
      for (int k = 0; k < c; ++k) out[k] += weight * p[k];
    }
  }
}

}  // namespace fvs
