// Triangle meshes and point clouds in double precision (positions), as read from and written
// to PLY (fused.ply, meshed-delaunay.ply).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace fvs {

using Vector3ub = Eigen::Matrix<uint8_t, 3, 1>;

struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> normals;  // empty or one per point
  std::vector<Vector3ub> colors;         // empty or one per point
  size_t size() const { return points.size(); }
};

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3f> normals;  // per vertex; empty or one per vertex
  std::vector<Vector3ub> colors;         // per vertex; empty or one per vertex
  std::vector<Eigen::Vector3i> faces;    // counter-clockwise seen from outside
  size_t num_faces() const { return faces.size(); }
};

}  // namespace fvs
