#include "fvs/scene/warp.h"

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

WarpMap ComputeWarpMap(const PinholeCamera& target, const Image& target_depth,
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

  const int w = target.width, h = target.height;
  WarpMap map;
  map.source_xy = Image(w, h, 2);
  map.valid_depth = Image(w, h, 1);
  map.valid_warp = Image(w, h, 1);
  map.source_z = Image(w, h, 1);

  // Relative pose target camera -> source camera, once, in double.
  const Eigen::Matrix3d R_rel = source.R * target.R.transpose();
  const Eigen::Vector3d t_rel = source.t - R_rel * target.t;
  const double tol = options.occlusion_tolerance;
  const double invalid = options.invalid_depth;
  std::vector<int64_t> valid_per_row(h, 0);

  ParallelFor(
      0, h,
      [&](int64_t y) {
        int64_t valid_count = 0;
        const double ny = (y + 0.5 - target.cy) / target.fy;
        for (int x = 0; x < w; ++x) {
          const float raw = target_depth.at(x, static_cast<int>(y));
          const bool surface = raw > 0 && std::isfinite(raw);
          const double d = EffectiveDepth(raw, invalid);
          const double nx = (x + 0.5 - target.cx) / target.fx;
          const Eigen::Vector3d X = R_rel * Eigen::Vector3d(nx * d, ny * d, d) + t_rel;
          const size_t i = static_cast<size_t>(y) * w + x;
          map.valid_depth.data[i] = surface ? 1.f : 0.f;
          float u_out = -1.f, v_out = -1.f, z_out = 0.f, ok = 0.f;
          // Z relative to the scale of the point: a point behind or at the source centre
          // has no projection.
          if (X.z() > 1e-12 * std::max(1.0, X.norm())) {
            const double u = source.fx * X.x() / X.z() + source.cx;
            const double v = source.fy * X.y() / X.z() + source.cy;
            if (std::isfinite(u) && std::isfinite(v)) {
              // Keep far-off coordinates finite in float and clearly outside.
              const double lim = 1e7 + 4.0 * std::max(source.width, source.height);
              u_out = static_cast<float>(std::clamp(u, -lim, lim));
              v_out = static_cast<float>(std::clamp(v, -lim, lim));
              z_out = static_cast<float>(std::min(X.z(), 1e30));
              if (u >= 0 && v >= 0 && u < source.width && v < source.height &&
                  SourceSeesDepth(source_depth, u, v, X.z(), tol, invalid)) {
                ok = 1.f;
              }
            }
          }
          map.source_xy.data[2 * i] = u_out;
          map.source_xy.data[2 * i + 1] = v_out;
          map.source_z.data[i] = z_out;
          map.valid_warp.data[i] = ok;
          valid_count += ok > 0;
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

}  // namespace fvs
