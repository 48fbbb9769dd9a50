#include "fvs/scene/scene.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/geometry/ply.h"
#include "fvs/geometry/rasterizer.h"
#include "fvs/scene/backdrop.h"
#include "fvs/scene/depth_cache.h"
#include "fvs/scene/photo_quality.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {

namespace {

// `what` names the mesh in the message: "the proxy mesh", "the backdrop".
void CheckMesh(const TriangleMesh& mesh, const std::string& subject,
               const std::string& what = "the proxy mesh") {
  Require(!mesh.vertices.empty() && !mesh.faces.empty(), subject,
          what + " has no triangles");
  for (const auto& v : mesh.vertices) {
    Require(v.allFinite(), subject, what + " has a non-finite vertex");
  }
}

}  // namespace

void Scene::Centre(const std::vector<SceneView>& world_views,
                   const TriangleMesh& world_mesh) {
  Require(!world_views.empty(), workspace_path_, "the scene has no registered images");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const SceneView& v : world_views) {
    Require(v.camera.IsValid(), v.name, "invalid camera (non-finite or degenerate)");
    sum += v.camera.Center();
  }
  origin_ = sum / static_cast<double>(world_views.size());
  views_ = world_views;
  for (SceneView& v : views_) v.camera = ToSceneCamera(v.camera);
  mesh_ = world_mesh;
  for (Eigen::Vector3d& x : mesh_.vertices) x -= origin_;
  source_images_.assign(views_.size(), nullptr);
}

PinholeCamera Scene::ToSceneCamera(const PinholeCamera& world_camera) const {
  // x_cam = R (x_scene + o) + t = R x_scene + (R o + t).
  PinholeCamera c = world_camera;
  c.t = world_camera.t + world_camera.R * origin_;
  return c;
}

PinholeCamera Scene::ToWorldCamera(const PinholeCamera& scene_camera) const {
  PinholeCamera c = scene_camera;
  c.t = scene_camera.t - scene_camera.R * origin_;
  return c;
}

int Scene::FindView(const std::string& name) const {
  for (int i = 0; i < num_views(); ++i) {
    if (views_[i].name == name) return i;
  }
  return -1;
}

Image Scene::RenderDepth(const PinholeCamera& scene_camera) const {
  return RenderWithBackdrop(mesh_, backdrop_, scene_camera, num_threads_);
}

Image Scene::RenderMeshDepth(const PinholeCamera& scene_camera) const {
  RasterizeOptions options;
  options.num_threads = num_threads_;
  return Rasterize(mesh_, scene_camera, options).depth;
}

const Image& Scene::SourceImage(int i) const {
  {
    std::lock_guard<std::mutex> lock(*image_mutex_);
    if (source_images_.at(i)) return *source_images_[i];
  }
  Require(!workspace_path_.empty(), views_.at(i).name,
          "no photo set for this view of an in-memory scene");
  const std::string path =
      colmap::DenseWorkspace(workspace_path_).ImagePath(views_[i].name);
  // Read outside the lock: two threads may read the same file once each; the first wins.
  auto image = std::make_shared<Image>(colmap::ReadImage(path, 3));
  const PinholeCamera& cam = views_[i].camera;
  Require(image->width == cam.width && image->height == cam.height, path,
          "image is " + std::to_string(image->width) + "x" +
              std::to_string(image->height) + " but its camera is " +
              std::to_string(cam.width) + "x" + std::to_string(cam.height) +
              " (not an undistorted dense workspace?)");
  std::lock_guard<std::mutex> lock(*image_mutex_);
  if (!source_images_[i]) source_images_[i] = std::move(image);
  return *source_images_[i];
}

void Scene::SetSourceImage(int i, Image image) {
  const PinholeCamera& cam = views_.at(i).camera;
  Require(image.width == cam.width && image.height == cam.height && image.channels == 3,
          views_[i].name, "photo size or channel count does not match the camera");
  std::lock_guard<std::mutex> lock(*image_mutex_);
  source_images_[i] = std::make_shared<Image>(std::move(image));
}

Scene Scene::FromWorld(const std::vector<SceneView>& world_views,
                       const TriangleMesh& world_mesh, int num_threads) {
  Timer timer;
  Scene scene;
  scene.num_threads_ = num_threads;
  CheckMesh(world_mesh, "in-memory scene");
  scene.Centre(world_views, world_mesh);
  for (const SceneView& v : scene.views_) {
    scene.source_depths_.push_back(std::make_shared<Image>(scene.RenderDepth(v.camera)));
    ++scene.num_depths_computed_;
  }
  scene.load_seconds_ = timer.Seconds();
  return scene;
}

Scene Scene::Load(const std::string& workspace_path, const SceneLoadOptions& options) {
  Timer timer;
  Scene scene;
  scene.workspace_path_ = workspace_path;
  scene.num_threads_ = options.num_threads;
  const colmap::DenseWorkspace workspace(workspace_path);
  Require(std::filesystem::is_directory(workspace_path), workspace_path,
          "workspace folder does not exist");
  Require(std::filesystem::is_directory(workspace.SparseDir()), workspace.SparseDir(),
          "no sparse model (run colmap image_undistorter or view_synthesis_prepare)");
  const std::string mesh_path = workspace.ProxyMeshPath();
  Require(std::filesystem::is_regular_file(mesh_path), mesh_path,
          "no proxy mesh (run colmap view_synthesis_prepare or view_synthesis_mesher)");
  const char* quiet = std::getenv("FVS_QUIET");  // as the progress lines
  if (mesh_path == workspace.SceneRefinedMeshPath() && !(quiet && quiet[0] == '1')) {
    std::cerr << "using the scene-refined mesh " << mesh_path
              << " (view_synthesis_refine)\n";
  }

  const colmap::Reconstruction reconstruction =
      colmap::ReadSparseModel(workspace.SparseDir());
  reconstruction.Check(workspace.SparseDir());
  std::vector<SceneView> views;
  for (const auto& [image_id, image] : reconstruction.images) {
    SceneView v;
    v.name = image.name;
    v.image_id = image_id;
    v.camera_id = image.camera_id;
    v.camera = reconstruction.PinholeFor(image_id);
    views.push_back(std::move(v));
  }
  const PhotoQualityReport quality =
      ReadPhotoQualityReport(PhotoQualityPath(workspace_path));
  for (const PhotoQuality& q : quality.photos) {
    if (!q.blurry) continue;
    for (SceneView& v : views) v.blurry = v.blurry || v.name == q.name;
  }
  const TriangleMesh mesh = ReadPlyMesh(mesh_path);
  CheckMesh(mesh, mesh_path);
  scene.Centre(views, mesh);
  const std::string backdrop_path = workspace.FvsDir() + "/backdrop.ply";
  if (std::filesystem::is_regular_file(backdrop_path)) {
    scene.backdrop_ = ReadPlyMesh(backdrop_path);
    CheckMesh(scene.backdrop_, backdrop_path, "the backdrop");
    for (Eigen::Vector3d& x : scene.backdrop_.vertices) x -= scene.origin_;
  }

  SourceDepthCache cache(workspace_path, mesh_path, backdrop_path,
                         options.use_depth_cache);
  Progress progress("source depths", scene.num_views());
  for (const SceneView& v : scene.views_) {
    // The cache keys on the world camera: the scene origin may move when views change.
    const PinholeCamera world = scene.ToWorldCamera(v.camera);
    std::shared_ptr<Image> depth = cache.Find(v.name, world);
    if (!depth) {
      depth = std::make_shared<Image>(scene.RenderDepth(v.camera));
      cache.Store(v.name, world, *depth);
      ++scene.num_depths_computed_;
    }
    scene.source_depths_.push_back(std::move(depth));
    progress.Advance();
  }
  progress.Finish();
  cache.Commit();
  scene.load_seconds_ = timer.Seconds();
  return scene;
}

std::string WorkspaceFinetunedModelDir(const std::string& workspace_path) {
  return (std::filesystem::path(workspace_path) / "fvs" / "finetuned").string();
}

}  // namespace fvs
