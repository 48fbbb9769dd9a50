// A prepared scene: the registered (undistorted, pinhole) cameras of a COLMAP dense
// workspace, the proxy mesh, the depth of every source view rendered from that mesh, and
// the source photos (loaded lazily).
//
// Everything is held in scene-centred coordinates: the mean camera centre (double) is
// subtracted from the mesh vertices and the camera translations on load, so that a scene
// 10 km from the origin is processed exactly as one at the origin. origin() gives the
// offset (world = scene + origin); ToSceneCamera / ToWorldCamera move cameras between the
// frames.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/util/image.h"

namespace fvs {

struct SceneView {
  std::string name;        // image name in the workspace (may contain '/')
  uint32_t image_id = 0;   // COLMAP image id (0 for in-memory scenes)
  uint32_t camera_id = 0;  // COLMAP camera id (0 for in-memory scenes)
  PinholeCamera camera;    // scene-centred
  // prepare found the photo blurry (W/fvs/photo_quality.json, scene/photo_quality.h):
  // the renderers use it as a source of last resort.
  bool blurry = false;
};

struct SceneLoadOptions {
  // Reuse / write the source depth cache under W/fvs/depth/.
  bool use_depth_cache = true;
  int num_threads = 0;  // <= 0: DefaultNumThreads()
};

class Scene {
 public:
  // Loads W/sparse (via ReadSparseModel), the proxy mesh (W/meshed-refined.ply where
  // prepare refined it, else W/meshed-delaunay.ply), the backdrop
  // W/fvs/backdrop.ply when prepare fitted one (scene/backdrop.h), and the source depth
  // cache (computing what is missing or stale). Throws fvs::Error naming what is missing
  // or bad.
  static Scene Load(const std::string& workspace_path,
                    const SceneLoadOptions& options = {});

  // An in-memory scene (tests, generated scenes): cameras and mesh in world coordinates;
  // they are centred here and the source depths rendered from the mesh.
  static Scene FromWorld(const std::vector<SceneView>& world_views,
                         const TriangleMesh& world_mesh, int num_threads = 0);

  Scene(Scene&&) = default;
  Scene& operator=(Scene&&) = default;

  int num_views() const { return static_cast<int>(views_.size()); }
  const SceneView& view(int i) const { return views_.at(i); }
  const std::vector<SceneView>& views() const { return views_; }
  // Index of the view with this image name, -1 if none.
  int FindView(const std::string& name) const;

  const TriangleMesh& mesh() const { return mesh_; }  // scene-centred
  // What lies beyond the mesh (scene/backdrop.h), scene-centred; no faces when none.
  const TriangleMesh& backdrop() const { return backdrop_; }
  const Eigen::Vector3d& origin() const { return origin_; }
  const std::string& workspace_path() const { return workspace_path_; }

  PinholeCamera ToSceneCamera(const PinholeCamera& world_camera) const;
  PinholeCamera ToWorldCamera(const PinholeCamera& scene_camera) const;

  // Depth of source view i rendered from the mesh (1 channel, 0 = no surface), at the
  // view's resolution.
  const Image& SourceDepth(int i) const { return *source_depths_.at(i); }
  // The photo of view i, RGB in [0, 1], read on first use (thread-safe). Throws
  // fvs::Error if the file is missing or its size differs from the camera's.
  const Image& SourceImage(int i) const;
  // For in-memory scenes: sets the photo of view i (size must match the camera).
  void SetSourceImage(int i, Image image);

  // Depth seen by a scene-centred camera (1 channel, 0 = no surface): the mesh, and the
  // backdrop where the mesh has no surface (RenderWithBackdrop). Every source depth and
  // every target depth is this.
  Image RenderDepth(const PinholeCamera& scene_camera) const;
  // The mesh alone (what the mesh's coverage measures).
  Image RenderMeshDepth(const PinholeCamera& scene_camera) const;

  // Seconds spent loading (sparse model, mesh, depth cache); for reports.
  double load_seconds() const { return load_seconds_; }
  int num_depths_computed() const { return num_depths_computed_; }

 private:
  Scene() = default;
  void Centre(const std::vector<SceneView>& world_views, const TriangleMesh& world_mesh);

  std::string workspace_path_;  // empty for in-memory scenes
  std::vector<SceneView> views_;
  TriangleMesh mesh_;
  TriangleMesh backdrop_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  std::vector<std::shared_ptr<const Image>> source_depths_;
  // Lazily loaded photos; the mutex is held only to publish a loaded image.
  mutable std::vector<std::shared_ptr<const Image>> source_images_;
  mutable std::unique_ptr<std::mutex> image_mutex_ = std::make_unique<std::mutex>();
  double load_seconds_ = 0;
  int num_depths_computed_ = 0;
  int num_threads_ = 0;

  friend class SceneLoader;
};

// W/fvs/finetuned: a scene's own weights (<variant>.safetensors and .json), written by
// view_synthesis_finetune (train/finetune.h) and used by the renderer before the shipped
// ones.
std::string WorkspaceFinetunedModelDir(const std::string& workspace_path);

}  // namespace fvs
