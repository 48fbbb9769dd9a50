// A small analytic scene for testing and benchmarking the stereo stage: textured planes
// (a floor, a back wall and a box) seen by a row of cameras, ray-cast with exact depth.
// The texture is smooth value noise (a few pixels per feature at the rendered size) so
// that every surface pixel is textured and NCC has something to match; or plain tiles
// with textured grout (AnalyticSceneOptions::tile_size).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs::mvs {

struct AnalyticSceneOptions {
  int num_views = 6;
  int width = 160;
  int height = 120;
  uint64_t seed = 1;
  int num_sparse_points = 1500;  // surface samples written as the sparse model
  int supersampling = 3;  // per axis, for the colours (depth is the pixel centre's)
  // > 0: every surface is tiled, plain tiles of this side (world units) with textured
  // grout lines a tenth as wide between them, the textureless case of a tiled wall.
  double tile_size = 0;
};

struct AnalyticScene {
  std::vector<std::string> names;  // "view_000.png", ...
  std::vector<PinholeCamera> cameras;
  std::vector<Image> images;  // 3 channels (grey texture repeated), [0, 1]
  std::vector<Image> depths;  // exact camera-frame z, 0 where no surface
  // Surface samples seen by at least two views: the world point and, per view, the pixel
  // (COLMAP convention) where it is seen (unseen views are absent).
  struct Track {
    Eigen::Vector3d xyz;
    std::vector<std::pair<int, Eigen::Vector2d>> observations;
  };
  std::vector<Track> tracks;
};

AnalyticScene RenderAnalyticScene(const AnalyticSceneOptions& options);

// Writes the scene as a COLMAP dense workspace (what image_undistorter writes):
// dir/images (PNG), dir/sparse (binary model, PINHOLE cameras, points3D with tracks),
// plus dir/ground_truth/<name>.bin depth maps in COLMAP's array format.
void WriteAnalyticWorkspace(const AnalyticScene& scene, const std::string& dir);

}  // namespace fvs::mvs
