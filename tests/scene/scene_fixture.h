// A small closed test world shared by the scene and render tests: a room (box seen from
// inside) with a box object on the floor, every face finely tessellated with smoothly
// varying vertex colours (a Lambertian "texture"), and cameras on an arc looking at the
// object. Ground-truth photos of any camera come from Rasterize with compute_color, so a
// held-out view has an exact reference. `offset` translates the whole world
// (far-from-origin tests).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "colmap_ext/image_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/look_at.h"
#include "fvs/geometry/ply.h"
#include "fvs/geometry/quad_grid.h"
#include "fvs/geometry/rasterizer.h"
#include "fvs/scene/scene.h"

namespace fvs::testing {

// A grid of (nu x nv) quads spanning corner + [0,1] u + [0,1] v, colours from the
// position (fvs/geometry/quad_grid.h).
inline void AddQuadGrid(TriangleMesh* mesh, const Eigen::Vector3d& corner,
                        const Eigen::Vector3d& u, const Eigen::Vector3d& v, int nu,
                        int nv, const Eigen::Vector3d& offset) {
  AddColouredQuadGrid(mesh, corner, u, v, nu, nv, offset);
}

// Room x in [-5, 5], y in [-4, 4], z in [0, 3]; box [-0.7, 0.7] x [-0.5, 0.5] x [0, 1.2].
inline TriangleMesh MakeTestWorldMesh(
    const Eigen::Vector3d& offset = Eigen::Vector3d::Zero(), double cell = 0.25) {
  TriangleMesh mesh;
  auto box = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    const Eigen::Vector3d s = hi - lo;
    const Eigen::Vector3d ex(s.x(), 0, 0), ey(0, s.y(), 0), ez(0, 0, s.z());
    auto n = [&](const Eigen::Vector3d& e) {
      return std::max(1, static_cast<int>(std::lround(e.norm() / cell)));
    };
    AddQuadGrid(&mesh, lo, ex, ey, n(ex), n(ey), offset);
    AddQuadGrid(&mesh, lo + ez, ex, ey, n(ex), n(ey), offset);
    AddQuadGrid(&mesh, lo, ex, ez, n(ex), n(ez), offset);
    AddQuadGrid(&mesh, lo + ey, ex, ez, n(ex), n(ez), offset);
    AddQuadGrid(&mesh, lo, ey, ez, n(ey), n(ez), offset);
    AddQuadGrid(&mesh, lo + ex, ey, ez, n(ey), n(ez), offset);
  };
  box({-5, -4, 0}, {5, 4, 3});
  box({-0.7, -0.5, 0}, {0.7, 0.5, 1.2});
  return mesh;
}

inline PinholeCamera LookAtCamera(const Eigen::Vector3d& eye,
                                  const Eigen::Vector3d& target, int width, int height,
                                  double focal_factor = 0.8) {
  return ::fvs::LookAtCamera(eye, target, width, height, focal_factor * width);
}

// The camera of arc position a (radians) around the box, at eye height.
inline PinholeCamera ArcCamera(double a, int width, int height,
                               const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  const Eigen::Vector3d eye(3.2 * std::cos(a), 2.6 * std::sin(a), 1.6);
  return LookAtCamera(eye + offset, Eigen::Vector3d(0, 0, 0.7) + offset, width, height);
}

// n views spread over `arc` radians starting at a0, named view_000.png, ...
inline std::vector<SceneView> ArcViews(
    int n, int width, int height, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero(),
    double a0 = -0.6, double arc = 1.2) {
  std::vector<SceneView> views;
  for (int i = 0; i < n; ++i) {
    SceneView v;
    char name[32];
    std::snprintf(name, sizeof(name), "view_%03d.png", i);
    v.name = name;
    v.image_id = i + 1;
    v.camera_id = 1;
    v.camera = ArcCamera(a0 + (n > 1 ? arc * i / (n - 1) : 0.0), width, height, offset);
    views.push_back(v);
  }
  return views;
}

inline Image RenderGroundTruth(const TriangleMesh& mesh, const PinholeCamera& camera) {
  RasterizeOptions options;
  options.compute_color = true;
  return Rasterize(mesh, camera, options).color;
}

// An in-memory scene with ground-truth photos.
inline Scene MakeTestScene(int num_views, int width, int height,
                           const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  const TriangleMesh mesh = MakeTestWorldMesh(offset);
  const std::vector<SceneView> views = ArcViews(num_views, width, height, offset);
  Scene scene = Scene::FromWorld(views, mesh);
  for (int i = 0; i < num_views; ++i) {
    scene.SetSourceImage(i, RenderGroundTruth(mesh, views[i].camera));
  }
  return scene;
}

// A COLMAP dense workspace: images/*.png, sparse/ (text model, one PINHOLE camera per
// view), meshed-delaunay.ply (double precision).
inline void WriteTestWorkspace(const std::string& root,
                               const std::vector<SceneView>& views,
                               const TriangleMesh& mesh, bool write_mesh = true) {
  std::filesystem::create_directories(root + "/images");
  std::filesystem::create_directories(root + "/sparse");
  colmap::Reconstruction rec;
  for (size_t i = 0; i < views.size(); ++i) {
    const PinholeCamera& c = views[i].camera;
    colmap::Camera camera;
    camera.camera_id = static_cast<uint32_t>(i + 1);
    camera.model_id = 1;  // PINHOLE
    camera.width = c.width;
    camera.height = c.height;
    camera.params = {c.fx, c.fy, c.cx, c.cy};
    rec.cameras[camera.camera_id] = camera;
    colmap::Image image;
    image.image_id = static_cast<uint32_t>(i + 1);
    image.camera_id = camera.camera_id;
    image.name = views[i].name;
    image.qvec = RotationToQuaternion(c.R);
    image.tvec = c.t;
    rec.images[image.image_id] = image;
    colmap::WriteImage(root + "/images/" + views[i].name, RenderGroundTruth(mesh, c));
  }
  colmap::WriteSparseModelText(root + "/sparse", rec);
  if (write_mesh) {
    PlyWriteOptions options;
    options.double_precision = true;
    WritePlyMesh(root + "/meshed-delaunay.ply", mesh, options);
  }
}

inline double Psnr(const Image& a, const Image& b) {
  double se = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const double d = a.data[i] - b.data[i];
    se += d * d;
  }
  const double mse = se / std::max<size_t>(1, a.data.size());
  return mse > 0 ? 10 * std::log10(1.0 / mse) : 99.0;
}

inline bool AllFinite(const Image& image) {
  for (float v : image.data) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace fvs::testing
