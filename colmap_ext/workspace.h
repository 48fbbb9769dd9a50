// Paths of a COLMAP dense workspace (as written by image_undistorter) plus our fvs/
// folder:
//   W/images/  W/sparse/  W/stereo/{depth_maps,normal_maps}/<name>.<type>.bin
//   W/fused.ply(.vis)  W/meshed-delaunay.ply  W/fvs/
#pragma once

#include <string>

namespace fvs::colmap {

struct Reconstruction;  // reconstruction.h

struct DenseWorkspace {
  std::string root;

  explicit DenseWorkspace(std::string root_path) : root(std::move(root_path)) {}

  std::string ImagesDir() const { return root + "/images"; }
  std::string SparseDir() const { return root + "/sparse"; }
  std::string StereoDir() const { return root + "/stereo"; }
  std::string ImagePath(const std::string& name) const {
    return ImagesDir() + "/" + name;
  }
  // type: "photometric" or "geometric".
  std::string DepthMapPath(const std::string& name, const std::string& type) const {
    return root + "/stereo/depth_maps/" + name + "." + type + ".bin";
  }
  std::string NormalMapPath(const std::string& name, const std::string& type) const {
    return root + "/stereo/normal_maps/" + name + "." + type + ".bin";
  }
  std::string FusedPath() const { return root + "/fused.ply"; }
  std::string FusedVisPath() const { return root + "/fused.ply.vis"; }
  std::string DelaunayMeshPath() const { return root + "/meshed-delaunay.ply"; }
  // The Delaunay mesh refined by photo-consistency (prepare's mesh_refinement stage).
  std::string RefinedMeshPath() const { return root + "/meshed-refined.ply"; }
  // The mesh prepare leaves: the refined mesh where prepare made one, else the Delaunay
  // mesh.
  std::string PreparedMeshPath() const;
  // That mesh refined per scene by the photo-consistency of its renders
  // (view_synthesis_refine, train/scene_refine.h).
  std::string SceneRefinedMeshPath() const { return root + "/fvs/refine/mesh.ply"; }
  // The proxy mesh the renderers use: the scene-refined mesh where there is one no older
  // than prepare's (a prepare that meshes again makes it stale), else prepare's mesh.
  std::string ProxyMeshPath() const;
  std::string PoissonMeshPath() const { return root + "/meshed-poisson.ply"; }
  std::string FvsDir() const { return root + "/fvs"; }
  std::string SourceDepthPath(const std::string& name) const {
    return root + "/fvs/depth/" + name + ".bin";
  }
  std::string ManifestPath() const { return root + "/fvs/manifest.json"; }
};

// Throws fvs::Error naming what is missing when `root` has no images/ or no sparse model.
void CheckDenseWorkspace(const DenseWorkspace& workspace);
// Throws fvs::Error naming the first image of `reconstruction` that has no file in
// images/ (a workspace copied without all its images).
void CheckWorkspaceImages(const DenseWorkspace& workspace,
                          const Reconstruction& reconstruction);
// Creates a folder and its parents; throws fvs::Error on failure.
void CreateDirectories(const std::string& path);

}  // namespace fvs::colmap
