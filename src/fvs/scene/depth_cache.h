// The source depth cache of a workspace: W/fvs/depth/<image name>.bin (COLMAP array
// format, float32, 0 = no surface), one per registered image, plus W/fvs/depth/stamp.json
// which records the mesh file and the backdrop file (size, mtime; scene/backdrop.h) and
// each view's camera the depths were rendered with. A depth is reused only when the mesh,
// the backdrop and its camera are unchanged;
// everything else is recomputed by the caller and stored here.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs {

class SourceDepthCache {
 public:
  // enabled = false: Find always misses and nothing is written.
  SourceDepthCache(const std::string& workspace_path, const std::string& mesh_path,
                   const std::string& backdrop_path, bool enabled);

  // The cached depth of `name` rendered with `world_camera`, or nullptr.
  std::shared_ptr<Image> Find(const std::string& name, const PinholeCamera& world_camera);
  // Writes the depth file (atomically) and remembers its stamp.
  void Store(const std::string& name, const PinholeCamera& world_camera,
             const Image& depth);
  // Writes stamp.json (atomically) if anything was stored.
  void Commit();

  // The stamp string of a camera (all numbers at full precision).
  static std::string CameraStamp(const PinholeCamera& camera);

 private:
  std::string root_;
  std::string stamp_path_;
  bool enabled_ = true;
  bool dirty_ = false;
  nlohmann::json mesh_stamp_;
  nlohmann::json backdrop_stamp_;  // null when there is no backdrop file
  nlohmann::json views_ = nlohmann::json::object();
};

}  // namespace fvs
