// Synthetic inputs for testing and benchmarking the Delaunay mesher against a known
// surface: analytic boxes and spheres, pinhole cameras, fused points sampled as an MVS
// pipeline would produce them (uniform in image space, kept when at least two cameras see
// them), with Gaussian noise and outliers, plus the distances needed to score a mesh.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/look_at.h"
#include "fvs/geometry/mesh.h"
#include "fvs/mvs/delaunay.h"

namespace fvs::mvs {

struct ScenePrimitive {
  enum class Type { kBox, kSphere } type = Type::kBox;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_size = Eigen::Vector3d::Ones();  // box
  double radius = 1;                                    // sphere
  // A hollow primitive is seen from inside (a room: matter outside it); a solid one from
  // outside (an object).
  bool hollow = false;
};

struct MeshingScene {
  std::vector<ScenePrimitive> primitives;  // the true surface: union of their boundaries
  std::vector<PinholeCamera> cameras;

  // Distance from p to the nearest primitive boundary.
  double DistanceToSurface(const Eigen::Vector3d& p) const;
  // Smallest t > min_t where origin + t * dir meets a primitive boundary; +inf if none.
  double FirstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                  double min_t = 1e-9) const;
  // Unit normal of the nearest primitive boundary at p (pointing out of solids, into
  // hollow primitives: towards empty space).
  Eigen::Vector3d NormalAt(const Eigen::Vector3d& p) const;
  // True when p is in empty space: inside every hollow primitive, outside every solid
  // one.
  bool IsFree(const Eigen::Vector3d& p) const;
  // True when `p` (on the surface) is inside camera k's image and not occluded.
  bool Sees(size_t k, const Eigen::Vector3d& p) const;
};

// A room (10 x 6 x 3, seen from inside) with two boxes and a sphere on the floor, and
// `num_cameras` cameras on a ring looking across the room.
MeshingScene MakeRoomScene(int num_cameras, int width = 320, int height = 240);
// A sphere and a box seen from a ring of cameras outside them.
MeshingScene MakeObjectScene(int num_cameras, int width = 320, int height = 240);

struct SampledCloud {
  DelaunayMeshingInput input;  // noisy points + outliers, visibility, cameras
  std::vector<Eigen::Vector3d>
      true_points;  // the noise-free surface samples (no outliers)
  size_t num_outliers = 0;
};

// num_points surface points (noise: isotropic Gaussian of std `noise`), then
// outlier_fraction * num_points outliers uniform in the cameras' bounding volume, each
// "seen" by 2 random cameras whose image it falls in. Deterministic for a seed.
SampledCloud SampleScene(const MeshingScene& scene, size_t num_points, double noise,
                         double outlier_fraction, uint64_t seed);

// Distance from each query to the nearest triangle of `mesh`, capped at max_distance
// (exact below the cap).
std::vector<double> DistancesToMesh(const TriangleMesh& mesh,
                                    const std::vector<Eigen::Vector3d>& queries,
                                    double max_distance);

// Points on the faces of `mesh` (centroid plus `per_face` - 1 random barycentric points).
std::vector<Eigen::Vector3d> SampleMeshFaces(const TriangleMesh& mesh, int per_face,
                                             uint64_t seed);

struct MeshAccuracy {
  double vertex_mean = 0, vertex_p90 = 0;  // mesh vertices -> true surface
  double face_mean = 0, face_p90 = 0;      // face samples -> true surface
  double coverage = 0;  // fraction of true samples within coverage_distance of the mesh
};
MeshAccuracy EvaluateMesh(const MeshingScene& scene, const TriangleMesh& mesh,
                          const std::vector<Eigen::Vector3d>& true_points,
                          double coverage_distance);

}  // namespace fvs::mvs
