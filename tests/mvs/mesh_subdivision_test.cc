// Subdivision of long edges (mvs/mesh_subdivision.h): a square of two triangles before a
// camera is split where its edges are long in the photo, stays conforming (every inner
// edge in exactly two faces, once each way), keeps its orientation and area, and is left
// alone where the camera does not see it or its edges are already short.
#include "fvs/mvs/mesh_subdivision.h"

#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "fvs/geometry/look_at.h"

namespace fvs::mvs {
namespace {

// The square [-1, 1]^2 at z = 0, counter-clockwise seen from +z, coloured per corner.
TriangleMesh Square() {
  TriangleMesh mesh;
  mesh.vertices = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  mesh.colors = {{0, 0, 0}, {200, 0, 0}, {200, 200, 0}, {0, 200, 0}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

// 100 x 100 photo from +z that sees the whole square about 50 pixels wide.
PinholeCamera Above() {
  return LookAtCamera({0, 0, 4}, {0, 0, 0}, 100, 100, 100, Eigen::Vector3d::UnitY());
}

Eigen::Vector3d FaceNormalTimesTwiceArea(const TriangleMesh& m,
                                         const Eigen::Vector3i& f) {
  return (m.vertices[f[1]] - m.vertices[f[0]]).cross(m.vertices[f[2]] - m.vertices[f[0]]);
}

void ExpectConformingAndUpFacing(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> directed;
  double area = 0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d n = FaceNormalTimesTwiceArea(mesh, f);
    EXPECT_GT(n.z(), 0) << "a face turned over";
    area += 0.5 * n.norm();
    for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
  }
  EXPECT_NEAR(area, 4.0, 1e-12);
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second;
    // An inner edge has its twin; a border edge lies on the square's outline.
    if (directed.count({edge.second, edge.first}) == 0) {
      const Eigen::Vector3d a = mesh.vertices[edge.first], b = mesh.vertices[edge.second];
      const bool on_border = (std::abs(a.x()) == 1 && a.x() == b.x()) ||
                             (std::abs(a.y()) == 1 && a.y() == b.y());
      EXPECT_TRUE(on_border) << "a crack at " << a.transpose() << " - " << b.transpose();
    }
  }
}

TEST(MeshSubdivisionTest, ProjectedLengthIsTheLongestInAPhotoThatSeesTheEdge) {
  const std::vector<PinholeCamera> cameras = {Above()};
  // 2 units at distance 4 with focal 100: 50 pixels.
  EXPECT_NEAR(ProjectedEdgePixels(cameras, {-1, 0, 0}, {1, 0, 0}), 50, 1e-9);
  // Behind the camera, or with its midpoint outside the photo: not seen.
  EXPECT_EQ(ProjectedEdgePixels(cameras, {-1, 0, 5}, {1, 0, 5}), 0);
  EXPECT_EQ(ProjectedEdgePixels(cameras, {9, 0, 0}, {11, 0, 0}), 0);
}

TEST(MeshSubdivisionTest, SplitsLongEdgesAndStaysConforming) {
  TriangleMesh mesh = Square();
  // Sides 50 px, the diagonal 71 px: split only the diagonal.
  EXPECT_EQ(SubdivideLongEdges({Above()}, 60, &mesh), 1);
  EXPECT_EQ(mesh.vertices.size(), 5u);
  EXPECT_EQ(mesh.faces.size(), 4u);
  EXPECT_EQ(mesh.colors.size(), mesh.vertices.size());
  EXPECT_EQ(mesh.colors[4], Vector3ub(100, 100, 0));
  ExpectConformingAndUpFacing(mesh);
  // Now every edge: faces with one, two and three split edges, all conforming.
  for (int pass = 0; pass < 3; ++pass) {
    const size_t faces_before = mesh.faces.size();
    EXPECT_GT(SubdivideLongEdges({Above()}, 14.0 - 4 * pass, &mesh), 0);
    EXPECT_LE(mesh.faces.size(), 4 * faces_before);
    ExpectConformingAndUpFacing(mesh);
  }
}

TEST(MeshSubdivisionTest, ShortOrUnseenEdgesAreLeftAlone) {
  TriangleMesh mesh = Square();
  EXPECT_EQ(SubdivideLongEdges({Above()}, 100, &mesh), 0);
  EXPECT_EQ(mesh.faces, Square().faces);
  const PinholeCamera away =
      LookAtCamera({0, 0, -4}, {0, 0, -8}, 100, 100, 100, Eigen::Vector3d::UnitY());
  EXPECT_EQ(SubdivideLongEdges({away}, 1, &mesh), 0);
  EXPECT_EQ(mesh.vertices.size(), 4u);
}

}  // namespace
}  // namespace fvs::mvs
