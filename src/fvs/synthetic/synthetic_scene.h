// The synthetic scene: the project's demo scene and the test fixture of every stage after
// it.
//
// What it is (everything is drawn from one seed, so a seed always gives the same scene):
// - A closed room (a box seen from inside, 9-11 m x 7-9 m x 2.8-3.4 m, world z up, floor
// at
//   z = 0), so every pixel of every view has a surface and an exact depth.
// - Objects on the floor: boxes of random size and yaw, tessellated spheres and cylinders
// and
//   a staircase in the middle of the room, and taller cabinets/pillars between the camera
//   path and the walls (background and parallax). No object comes near a camera.
// - Solid procedural materials (material.h), one per primitive and one per room face, so
// no
//   two surfaces look the same and SIFT finds features everywhere.
// - A handheld-like camera path: an arc (a loop for many views) of an ellipse around the
//   room centre at eye height, looking at the objects, with smooth low-frequency wobble
//   of position, aim and roll plus a little per-frame shake. Consecutive views overlap
//   strongly (6 degrees of arc per view by default) with baselines of ~0.3 m for
//   triangulation.
// - PINHOLE cameras, fx = fy = focal_factor * width, principal point at the image centre.
// Rendering (render.h) is an exact ray caster over the mesh: depth and normals from the
// pixel-centre ray, colour from a supersampled Lambert shading of the albedo.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/synthetic/bvh.h"
#include "fvs/synthetic/material.h"

namespace fvs {

struct SyntheticSceneOptions {
  int num_views = 40;
  int width = 640;
  int height = 480;
  uint64_t seed = 0;
  int supersampling = 2;  // s x s colour samples per pixel (1 = pixel centre only)
  bool write_proxy_mesh = false;  // also copy the mesh to DIR/meshed-delaunay.ply
  double focal_factor = 0.85;     // focal length in pixels / width
  double path_step_degrees =
      6.0;                       // arc between consecutive views (loop: at most 360 / n)
  int num_sparse_points = 3000;  // ground-truth points3D written with the sparse model
  // Walls, floor and ceiling of one plain colour each (textureless, as white walls and
  // black cloth are): the test of stereo where NCC says nothing. Off: the demo scene.
  bool plain_walls = false;

  // Throws fvs::Error("SyntheticScene", ...) for values out of range.
  void Check() const;
};

struct SyntheticScene {
  SyntheticSceneOptions options;
  // Vertex colours hold the albedo (sRGB, 8 bit) at each vertex.
  TriangleMesh mesh;
  std::vector<int> face_primitive;  // one per face
  std::vector<int> face_material;   // one per face, index into materials
  std::vector<synthetic::ProceduralMaterial> materials;
  std::vector<std::string> primitive_names;  // "room.floor", "box", "sphere", ...
  std::vector<PinholeCamera> cameras;        // one per view
  std::vector<std::string> image_names;      // frame_0000.png, ...
  synthetic::MeshBvh bvh;
  Eigen::AlignedBox3d bounds;                            // of the mesh (the room)
  double scene_size = 0;                                 // bounding-box diagonal
  Eigen::Vector3d key_light = Eigen::Vector3d::UnitZ();  // unit, towards the light
  Eigen::Vector3d fill_light = Eigen::Vector3d::UnitZ();

  int num_views() const { return static_cast<int>(cameras.size()); }
};

// Builds the mesh, materials and cameras (no rendering). Throws fvs::Error on bad
// options.
SyntheticScene BuildSyntheticScene(const SyntheticSceneOptions& options);

}  // namespace fvs
