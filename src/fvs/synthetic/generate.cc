#include "fvs/synthetic/generate.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/geometry/ply.h"
#include "fvs/synthetic/ground_truth.h"
#include "fvs/synthetic/render.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

nlohmann::json OptionsToJson(const SyntheticSceneOptions& o) {
  return {{"num_views", o.num_views},
          {"width", o.width},
          {"height", o.height},
          {"seed", o.seed},
          {"supersampling", o.supersampling},
          {"write_proxy_mesh", o.write_proxy_mesh},
          {"focal_factor", o.focal_factor},
          {"path_step_degrees", o.path_step_degrees},
          {"num_sparse_points", o.num_sparse_points},
          {"plain_walls", o.plain_walls}};
}

void CheckFinite(const Image& image, const std::string& path) {
  for (float v : image.data) {
    if (!std::isfinite(v)) throw Error(path, "non-finite value rendered");
  }
}

}  // namespace

std::string SyntheticDepthMapPath(const std::string& output_dir,
                                  const std::string& name) {
  return output_dir + "/ground_truth/depth_maps/" + name + ".bin";
}
std::string SyntheticNormalMapPath(const std::string& output_dir,
                                   const std::string& name) {
  return output_dir + "/ground_truth/normal_maps/" + name + ".bin";
}
std::string SyntheticMeshPath(const std::string& output_dir) {
  return output_dir + "/ground_truth/mesh.ply";
}
std::string SyntheticSceneJsonPath(const std::string& output_dir) {
  return output_dir + "/ground_truth/scene.json";
}

void GenerateSyntheticScene(const SyntheticSceneOptions& options,
                            const std::string& output_dir) {
  options.Check();
  Require(!output_dir.empty(), "output_path", "must not be empty");
  const colmap::DenseWorkspace workspace(output_dir);
  // A stale scene.json would mark a half-rewritten folder as complete.
  std::remove(SyntheticSceneJsonPath(output_dir).c_str());
  colmap::CreateDirectories(workspace.ImagesDir());
  colmap::CreateDirectories(workspace.SparseDir());
  colmap::CreateDirectories(output_dir + "/ground_truth/depth_maps");
  colmap::CreateDirectories(output_dir + "/ground_truth/normal_maps");

  const SyntheticScene scene = BuildSyntheticScene(options);
  WritePlyMesh(SyntheticMeshPath(output_dir), scene.mesh);
  if (options.write_proxy_mesh) WritePlyMesh(workspace.DelaunayMeshPath(), scene.mesh);
  colmap::WriteSparseModelBinary(workspace.SparseDir(), SyntheticGroundTruthModel(scene));

  Progress progress("Rendering synthetic views", scene.num_views());
  for (int i = 0; i < scene.num_views(); ++i) {
    const std::string& name = scene.image_names[i];
    Image color, depth, normals;
    RenderSyntheticView(scene, scene.cameras[i], &color, &depth, &normals);
    CheckFinite(color, workspace.ImagePath(name));
    CheckFinite(depth, SyntheticDepthMapPath(output_dir, name));
    CheckFinite(normals, SyntheticNormalMapPath(output_dir, name));
    colmap::WriteImage(workspace.ImagePath(name), color);
    colmap::WriteColmapArray(SyntheticDepthMapPath(output_dir, name), depth);
    colmap::WriteColmapArray(SyntheticNormalMapPath(output_dir, name), normals);
    progress.Advance();
  }
  progress.Finish();

  nlohmann::json primitives = nlohmann::json::array();
  for (const std::string& p : scene.primitive_names) primitives.push_back(p);
  const nlohmann::json info = {
      {"generator", "colmap-fvs synthetic scene v1"},
      {"seed", options.seed},
      {"options", OptionsToJson(options)},
      {"scene_size", scene.scene_size},
      {"bounds_min",
       {scene.bounds.min().x(), scene.bounds.min().y(), scene.bounds.min().z()}},
      {"bounds_max",
       {scene.bounds.max().x(), scene.bounds.max().y(), scene.bounds.max().z()}},
      {"num_vertices", scene.mesh.vertices.size()},
      {"num_faces", scene.mesh.faces.size()},
      {"primitives", primitives},
      {"up", {0, 0, 1}},
      {"image_names", scene.image_names}};
  WriteFileAtomic(SyntheticSceneJsonPath(output_dir),
                  [&](std::ostream& out) { out << info.dump(2) << "\n"; });
}

void RenderSyntheticFrames(
    const SyntheticSceneOptions& options,
    const std::vector<std::pair<std::string, PinholeCamera>>& frames,
    const std::string& output_dir) {
  options.Check();
  for (const auto& [name, camera] : frames) {
    Require(camera.IsValid(), name, "invalid camera");
  }
  colmap::CreateDirectories(output_dir);
  const SyntheticScene scene = BuildSyntheticScene(options);
  Progress progress("Rendering ground-truth frames", static_cast<int64_t>(frames.size()));
  for (const auto& [name, camera] : frames) {
    const std::string path = output_dir + "/" + name + ".png";
    if (!colmap::IsCompleteImage(path, camera.width, camera.height)) {
      Image color, depth, normals;
      RenderSyntheticView(scene, camera, &color, &depth, &normals);
      CheckFinite(color, path);
      colmap::WriteImage(path, color);
    }
    progress.Advance();
  }
  progress.Finish();
}

}  // namespace fvs
