#include "fvs/path/flicker.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "fvs/geometry/warp.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {

namespace {

void RequireSize(const Image& image, const PinholeCamera& camera, int channels,
                 const std::string& what) {
  Require(image.width == camera.width && image.height == camera.height &&
              image.channels == channels,
          "flicker",
          what + " does not match its camera (" + std::to_string(image.width) + "x" +
              std::to_string(image.height) + "x" + std::to_string(image.channels) + ")");
}

}  // namespace

void FlickerOptions::Check() const {
  Require(std::isfinite(depth_tolerance) && depth_tolerance > 0, "flicker",
          "depth_tolerance must be positive");
}

WarpedFrame WarpFrame(const Image& prev_color, const Image& prev_depth,
                      const PinholeCamera& prev_camera, const Image& next_depth,
                      const PinholeCamera& next_camera, const FlickerOptions& options,
                      const Image* prev_mask) {
  options.Check();
  Require(prev_camera.IsValid() && next_camera.IsValid(), "flicker", "invalid camera");
  RequireSize(prev_color, prev_camera, 3, "previous colour");
  RequireSize(prev_depth, prev_camera, 1, "previous depth");
  RequireSize(next_depth, next_camera, 1, "next depth");
  if (prev_mask) RequireSize(*prev_mask, prev_camera, 1, "previous mask");
  const int w = next_camera.width, h = next_camera.height;
  WarpedFrame out{Image(w, h, 3), Image(w, h, 1)};
  // Relative pose next -> prev, in double precision.
  const Eigen::Matrix3d R = prev_camera.R * next_camera.R.transpose();
  const Eigen::Vector3d t = prev_camera.t - R * next_camera.t;
  constexpr double kInvalidDepth = 1e9;
  ParallelFor(0, h, [&](int64_t y) {
    float sample[3];
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const double d = next_depth.data[i];
      if (!(d > 0) || !std::isfinite(d)) continue;  // compare surfaces only
      const Eigen::Vector3d p = R * next_camera.PixelToCamera(x + 0.5, y + 0.5, d) + t;
      if (!(p.z() > 0)) continue;
      const Eigen::Vector2d uv = prev_camera.CameraToPixel(p);
      if (!(uv.x() >= 0 && uv.y() >= 0 && uv.x() < prev_camera.width &&
            uv.y() < prev_camera.height)) {
        continue;
      }
      if (!SourceSeesDepth(prev_depth, uv.x(), uv.y(), p.z(), options.depth_tolerance,
                           kInvalidDepth)) {
        continue;
      }
      if (prev_mask) {
        const int px = std::min(prev_camera.width - 1, static_cast<int>(uv.x()));
        const int py = std::min(prev_camera.height - 1, static_cast<int>(uv.y()));
        if (!(prev_mask->at(px, py) > 0)) continue;
      }
      SampleBilinear(prev_color, uv.x(), uv.y(), sample, true);
      for (int c = 0; c < 3; ++c) {
        out.color.data[3 * i + c] = std::isfinite(sample[c]) ? sample[c] : 0.f;
      }
      out.valid.data[i] = 1.f;
    }
  });
  return out;
}

FlickerPair MeasureFlicker(const Image& prev_color, const Image& prev_depth,
                           const PinholeCamera& prev_camera, const Image& next_color,
                           const Image& next_depth, const PinholeCamera& next_camera,
                           const FlickerOptions& options, const Image* prev_mask,
                           const Image* next_mask) {
  RequireSize(next_color, next_camera, 3, "next colour");
  if (next_mask) RequireSize(*next_mask, next_camera, 1, "next mask");
  const WarpedFrame warped = WarpFrame(prev_color, prev_depth, prev_camera, next_depth,
                                       next_camera, options, prev_mask);
  FlickerPair pair;
  double abs_sum = 0, sq_sum = 0;
  const size_t n = static_cast<size_t>(next_camera.width) * next_camera.height;
  for (size_t i = 0; i < n; ++i) {
    if (!(warped.valid.data[i] > 0)) continue;
    if (next_mask && !(next_mask->data[i] > 0)) continue;
    ++pair.num_covisible;
    for (int c = 0; c < 3; ++c) {
      const double diff = 255.0 * (static_cast<double>(next_color.data[3 * i + c]) -
                                   warped.color.data[3 * i + c]);
      if (!std::isfinite(diff)) continue;
      abs_sum += std::abs(diff);
      sq_sum += diff * diff;
    }
  }
  if (pair.num_covisible > 0) {
    pair.mean_abs = abs_sum / (3.0 * pair.num_covisible);
    pair.rmse = std::sqrt(sq_sum / (3.0 * pair.num_covisible));
  }
  pair.covisible_fraction = n > 0 ? static_cast<double>(pair.num_covisible) / n : 0.0;
  return pair;
}

double MeanFlicker(const std::vector<FlickerPair>& pairs) {
  double sum = 0, weight = 0;
  for (const FlickerPair& p : pairs) {
    sum += p.mean_abs * p.num_covisible;
    weight += p.num_covisible;
  }
  return weight > 0 ? sum / weight : 0.0;
}

}  // namespace fvs
