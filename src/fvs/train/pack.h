// The packed training set: one folder per scene holding scene.safetensors, everything the
// trainer reads (doc/training.md documents the format):
//   images   U8  [N,3,H,W]  photos at `scale`, RGB
//   depths   F32 [N,H,W]    proxy-mesh depth of every view at that size (0 = no surface)
//   K        F64 [N,3,3]    intrinsics at that size (COLMAP pixel centres at +0.5)
//   R, t     F64 [N,3,3], [N,3]  scene-centred world-to-camera pose
//   overlap  F32 [N,N]      overlap[i][j]: fraction of i's surface pixels that j sees (in
//                           front, inside, within depth_tolerance of j's depth); diagonal
//                           0
//   __metadata__: fvs_pack_version, names (JSON list), workspace, scale, width, height,
//                 depth_tolerance, origin (JSON [x,y,z], world = scene + origin)
// Written from a prepared Scene (full build only: the trainer itself never needs COLMAP,
// OpenImageIO or the rasteriser, so this file is not part of the trainer-only build).
#pragma once

#include <string>

#include "fvs/util/image.h"
#include "fvs/util/image_resize.h"

namespace fvs {

class Scene;

inline constexpr char kPackedSceneFile[] = "scene.safetensors";
inline constexpr int kPackFormatVersion = 1;

struct PackOptions {
  double scale = 0.25;           // of the workspace images
  double depth_tolerance = 0.1;  // overlap ranking (the reference code's 10%)
  int num_threads = 0;           // <= 0: DefaultNumThreads()
  void Check() const;            // throws fvs::Error
};

struct PackSummary {
  int num_views = 0;
  int width = 0, height = 0;
  double mean_overlap = 0;  // mean of the off-diagonal entries
  double seconds = 0;
  std::string path;  // .../scene.safetensors
};

// Packs every view of `scene` into output_dir/scene.safetensors (atomic). All views get
// one size: round(scale x) of the most common image size (a view of another size is
// resized to it and its intrinsics scaled per axis). Throws fvs::Error for a scene with
// fewer than 2 views or a scale that leaves less than 16 pixels.
PackSummary PackScene(const Scene& scene, const PackOptions& options,
                      const std::string& output_dir);

}  // namespace fvs
