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
#include <tuple>
#include <vector>

#include "colmap_ext/image_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/look_at.h"
#include "fvs/geometry/ply.h"
#include "fvs/geometry/quad_grid.h"
#include "fvs/geometry/rasterizer.h"
#include "fvs/scene/scene.h"
#include "support/pinhole_model.h"

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

// An open world whose background lies beyond the proxy mesh: the floor and the box of
// the test room are the mesh, the photos also show a textured "sky" box 500 units out
// that the mesh does not have (as the sky or a far facade a real mesh never reaches).
// The sky's colour pattern is that of a box of +-20 blown up 25 times, so it keeps a
// period of about 0.15 rad (10 pixels at 96 x 72) and the cameras' baselines of about a
// unit move it by under 0.2 pixels: it is at infinity for the renderers.
inline TriangleMesh MakeTestFloorAndBoxMesh(double cell = 0.25) {
  TriangleMesh mesh;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  AddQuadGrid(&mesh, {-5, -4, 0}, {10, 0, 0}, {0, 8, 0}, 40, 32, zero);
  const Eigen::Vector3d lo(-0.7, -0.5, 0), ex(1.4, 0, 0), ey(0, 1.0, 0), ez(0, 0, 1.2);
  const int nx = std::lround(1.4 / cell), ny = std::lround(1.0 / cell),
            nz = std::lround(1.2 / cell);
  AddQuadGrid(&mesh, lo + ez, ex, ey, nx, ny, zero);
  AddQuadGrid(&mesh, lo, ex, ez, nx, nz, zero);
  AddQuadGrid(&mesh, lo + ey, ex, ez, nx, nz, zero);
  AddQuadGrid(&mesh, lo, ey, ez, ny, nz, zero);
  AddQuadGrid(&mesh, lo + ex, ey, ez, ny, nz, zero);
  return mesh;
}

inline TriangleMesh MakeTestSkyMesh() {
  TriangleMesh sky;
  const double r = 20;
  const Eigen::Vector3d lo(-r, -r, -r), zero = Eigen::Vector3d::Zero();
  const Eigen::Vector3d ex(2 * r, 0, 0), ey(0, 2 * r, 0), ez(0, 0, 2 * r);
  const int n = 40;
  for (const auto& [corner, u, v] :
       {std::make_tuple(lo, ex, ey), std::make_tuple(Eigen::Vector3d(lo + ez), ex, ey),
        std::make_tuple(lo, ex, ez), std::make_tuple(Eigen::Vector3d(lo + ey), ex, ez),
        std::make_tuple(lo, ey, ez), std::make_tuple(Eigen::Vector3d(lo + ex), ey, ez)}) {
    AddQuadGrid(&sky, corner, u, v, n, n, zero);
  }
  for (Eigen::Vector3d& p : sky.vertices) p *= 25.0;
  return sky;
}

// The scene of n arc views (ArcViews) over the floor and box, photos with the sky.
inline Scene MakeTestSkyScene(int num_views, int width, int height) {
  const TriangleMesh proxy = MakeTestFloorAndBoxMesh();
  TriangleMesh world = proxy;
  const TriangleMesh sky = MakeTestSkyMesh();
  const int base = static_cast<int>(world.vertices.size());
  world.vertices.insert(world.vertices.end(), sky.vertices.begin(), sky.vertices.end());
  world.colors.insert(world.colors.end(), sky.colors.begin(), sky.colors.end());
  for (const Eigen::Vector3i& f : sky.faces) {
    world.faces.push_back(f + Eigen::Vector3i::Constant(base));
  }
  const std::vector<SceneView> views = ArcViews(num_views, width, height);
  Scene scene = Scene::FromWorld(views, proxy);
  for (int i = 0; i < num_views; ++i) {
    scene.SetSourceImage(i, RenderGroundTruth(world, views[i].camera));
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
    AddPinholeImage(c, views[i].name, &rec);
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
