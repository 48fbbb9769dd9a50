// Exact ray casting against a triangle mesh: a bounding volume hierarchy (binned
// surface-area heuristic) over the triangles, traversed nearest child first, with the
// Moeller-Trumbore test in double precision. The BVH keeps its own copy of the triangles,
// so it stays valid when the mesh it was built from goes away.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "fvs/geometry/mesh.h"

namespace fvs::synthetic {

struct RayHit {
  double t = 0;  // hit point = origin + t * direction (direction need not be unit length)
  int face = -1;
  double u = 0, v = 0;  // barycentric coordinates of vertices 1 and 2
};

class MeshBvh {
 public:
  MeshBvh() = default;
  explicit MeshBvh(const TriangleMesh& mesh);

  // Nearest hit with t in (t_min, t_max); false when there is none.
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                 double t_min, double t_max, RayHit* hit) const;

  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  int num_nodes() const { return static_cast<int>(nodes_.size()); }
  // Unit normal of a face (right-hand rule on its vertex order).
  const Eigen::Vector3d& FaceNormal(int face) const { return triangles_[face].normal; }

 private:
  struct Triangle {
    Eigen::Vector3d v0, e1, e2, normal;
  };
  struct Node {
    Eigen::Vector3d lo, hi;
    int first = 0;  // leaf: first index into order_; inner: index of the right child
    int count = 0;  // > 0 for a leaf
  };

  int Build(int begin, int end, std::vector<Eigen::Vector3d>* centroids,
            std::vector<Eigen::Vector3d>* lo, std::vector<Eigen::Vector3d>* hi);

  std::vector<Triangle> triangles_;
  std::vector<int> order_;  // triangle ids, leaves refer to ranges of it
  std::vector<Node> nodes_;
};

}  // namespace fvs::synthetic
