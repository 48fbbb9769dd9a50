// Temporal stability of a rendered video. Flicker between frames t and t+1: every pixel
// of frame t+1 with a surface (target depth > 0) is unprojected with its depth, projected
// into frame t (poses in double precision, relative pose as in warp.h), and kept when it
// lands inside frame t, in front of it, and within depth_tolerance of frame t's own depth
// there (the occlusion check, warp.h's SourceSeesDepth); frame t's colour is sampled
// bilinearly there. Flicker = mean absolute colour difference over those co-visible
// pixels and channels, in 8-bit levels (0..255). For a static scene rendered
// consistently it is 0 up to resampling; noise, popping sources or shimmering blends
// raise it.
//
// The same warp serves to blend a frame with the warped previous output (WarpFrame).
#pragma once

#include <cstdint>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs {

struct FlickerOptions {
  double depth_tolerance = 0.01;  // relative, as the warp's occlusion check
  void Check() const;
};

struct FlickerPair {
  double mean_abs = 0;  // 8-bit levels, over co-visible pixels and channels
  double rmse = 0;      // 8-bit levels
  int64_t num_covisible = 0;
  double covisible_fraction = 0;  // of frame t+1's pixels
};

// Frame t (`prev`) and t+1 (`next`): colours (3 channels, [0, 1]), target depths (1
// channel, 0 = no surface) and cameras (one frame; any, the pose is relative). Optional
// masks (1 channel, > 0 = rendered): pixels outside either are not compared. Throws
// fvs::Error on size mismatches.
FlickerPair MeasureFlicker(const Image& prev_color, const Image& prev_depth,
                           const PinholeCamera& prev_camera, const Image& next_color,
                           const Image& next_depth, const PinholeCamera& next_camera,
                           const FlickerOptions& options = {},
                           const Image* prev_mask = nullptr,
                           const Image* next_mask = nullptr);

// Frame t warped into frame t+1's pixels; `valid` (1 channel) is 1 where co-visible.
struct WarpedFrame {
  Image color;
  Image valid;
};
WarpedFrame WarpFrame(const Image& prev_color, const Image& prev_depth,
                      const PinholeCamera& prev_camera, const Image& next_depth,
                      const PinholeCamera& next_camera,
                      const FlickerOptions& options = {},
                      const Image* prev_mask = nullptr);

// Mean of the pairs' mean_abs weighted by their co-visible pixels; 0 for none.
double MeanFlicker(const std::vector<FlickerPair>& pairs);

}  // namespace fvs
