// What the application shows of a workspace: the sparse points, the registered cameras,
// the proxy mesh, and (when it can render) the prepared fvs::Scene. Everything is in the
// scene-centred frame of fvs::Scene (world = scene + origin), in double precision until
// it is uploaded to OpenGL.
//
// A plain COLMAP dense workspace without meshed-delaunay.ply still opens: points and
// cameras are shown and render_error says why nothing can be rendered.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/scene/scene.h"

namespace fvs::ui {

struct WorkspaceContents {
  std::string path;
  std::string sparse_dir;                            // the model that was read
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // world = scene + origin
  std::vector<Eigen::Vector3d> points;               // sparse points, scene frame
  std::vector<Vector3ub> point_colors;               // one per point
  std::vector<std::string> view_names;               // registered images, by image id
  std::vector<PinholeCamera> cameras;                // one per view, scene frame
  TriangleMesh mesh;  // scene frame; empty when there is none
  // Null when the workspace cannot render (no mesh, missing photos...); render_error says
  // why, in one line naming the file.
  std::shared_ptr<const Scene> scene;
  std::string render_error;
  // Camera "up" in the scene (mean of the cameras' -y axes): orbiting turns around it.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  // Typical size of the scene (median camera distance to the points' centre, or the
  // camera spread): sets navigation speeds and clipping planes.
  double scale = 1.0;

  bool can_render() const { return scene != nullptr; }
  // Cameras between the scene frame and the WORLD frame (files hold world poses).
  PinholeCamera ToWorld(const PinholeCamera& scene_camera) const {
    PinholeCamera c = scene_camera;
    c.t = scene_camera.t - scene_camera.R * origin;
    return c;
  }
  PinholeCamera ToScene(const PinholeCamera& world_camera) const {
    PinholeCamera c = world_camera;
    c.t = world_camera.t + world_camera.R * origin;
    return c;
  }
  int num_views() const { return static_cast<int>(cameras.size()); }
};

// Reads W/sparse (or W/sparse/0, as COLMAP's mapper writes it) and, when
// W/meshed-delaunay.ply exists, the prepared scene (fvs::Scene::Load, which computes the
// source depth cache if needed). Throws fvs::Error naming the file when there is nothing
// to show (no such folder, no sparse model, a broken model).
WorkspaceContents LoadWorkspace(const std::string& path);

// Index of the camera whose centre projects nearest to pixel (x, y) of `view` (at most
// max_pixels away, in front of the view), -1 if none.
int PickCamera(const std::vector<PinholeCamera>& cameras, const PinholeCamera& view,
               double x, double y, double max_pixels);

}  // namespace fvs::ui
