// The faces the photos contradict (mvs/face_consistency.h): a textured wall seen by five
// photos, meshed together with a false surface floating in front of it (as the graph cut
// leaves across a gap no ray carved). The photos show only the wall, so through the
// false faces each photo sees a different part of the wall.
#include "fvs/mvs/face_consistency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "fvs/util/error.h"

namespace fvs::mvs {
namespace {

constexpr double kWallZ = 3.0, kFalseZ = 1.5;

Eigen::Vector3f WallColour(double x, double y) {
  return Eigen::Vector3f(0.5f + 0.4f * std::sin(20 * x), 0.5f + 0.4f * std::sin(17 * y),
                         0.5f + 0.4f * std::sin(13 * (x + y)));
}

PinholeCamera CameraAt(double x) {
  PinholeCamera c;
  c.width = 128;
  c.height = 96;
  c.fx = c.fy = 100;
  c.cx = 64;
  c.cy = 48;
  c.t = -Eigen::Vector3d(x, 0, 0);  // R = identity: looking along +z
  return c;
}

// The photo of the wall alone (the truth: nothing floats in front of it).
FaceConsistencyView Photo(double x) {
  FaceConsistencyView v;
  v.camera = CameraAt(x);
  v.photo = Image(v.camera.width, v.camera.height, 3);
  for (int py = 0; py < v.camera.height; ++py) {
    for (int px = 0; px < v.camera.width; ++px) {
      const Eigen::Vector3d p = v.camera.Unproject(px + 0.5, py + 0.5, kWallZ);
      const Eigen::Vector3f c = WallColour(p.x(), p.y());
      for (int k = 0; k < 3; ++k) v.photo.at(px, py, k) = c[k];
    }
  }
  return v;
}

std::vector<FaceConsistencyView> Photos() {
  std::vector<FaceConsistencyView> views;
  for (const double x : {-0.4, -0.2, 0.0, 0.2, 0.4}) views.push_back(Photo(x));
  return views;
}

// An n x n grid of quads (two faces each) over [-s, s]^2 at depth z, appended to mesh.
void AddGrid(double s, double z, int n, TriangleMesh* mesh) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh->vertices.emplace_back(-s + 2 * s * i / n, -s + 2 * s * j / n, z);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      mesh->faces.emplace_back(a, c, b);
      mesh->faces.emplace_back(b, c, d);
    }
  }
}

struct WallScene {
  TriangleMesh mesh;
  size_t num_wall_faces = 0;
};

WallScene WallWithFalseSurface() {
  WallScene s;
  AddGrid(4.0, kWallZ, 16, &s.mesh);
  s.num_wall_faces = s.mesh.faces.size();
  AddGrid(0.25, kFalseZ, 4, &s.mesh);
  return s;
}

FaceConsistencyOptions TestOptions() {
  FaceConsistencyOptions o;
  o.enabled = true;
  o.num_threads = 2;
  return o;
}

TEST(FaceConsistency, RemovesTheFalseSurfaceAndKeepsTheWall) {
  const WallScene scene = WallWithFalseSurface();
  const auto views = Photos();
  const FaceDifferences d = MeasureFaceDifferences(views, scene.mesh, TestOptions());
  double wall_max = 0;
  for (size_t f = 0; f < scene.num_wall_faces; ++f) {
    if (d.num_samples[f] >= 16) wall_max = std::max(wall_max, d.mean_difference[f]);
  }
  double false_min = std::numeric_limits<double>::max();
  for (size_t f = scene.num_wall_faces; f < scene.mesh.faces.size(); ++f) {
    ASSERT_GE(d.num_samples[f], 16u) << f;
    false_min = std::min(false_min, d.mean_difference[f]);
  }
  // The wall agrees to resampling error; the false faces disagree by far more.
  EXPECT_LT(wall_max, 0.03);
  EXPECT_GT(false_min, 0.1);

  const FaceConsistencyResult r =
      RemoveInconsistentFaces(views, scene.mesh, TestOptions());
  EXPECT_EQ(r.num_faces, scene.mesh.faces.size());
  EXPECT_EQ(r.num_removed, scene.mesh.faces.size() - scene.num_wall_faces);
  ASSERT_EQ(r.mesh.faces.size(), scene.num_wall_faces);
  for (size_t f = 0; f < scene.num_wall_faces; ++f)
    EXPECT_EQ(r.mesh.faces[f], scene.mesh.faces[f]);
  EXPECT_EQ(r.mesh.vertices, scene.mesh.vertices);
  EXPECT_GT(r.removed_area_share, 0.0);
  EXPECT_LT(r.median_difference, 0.03);
  EXPECT_NE(r.Summary().find("removed 32 of"), std::string::npos) << r.Summary();
}

TEST(FaceConsistency, KeepsEverythingWhenOffOrWithOnePhoto) {
  const WallScene scene = WallWithFalseSurface();
  FaceConsistencyOptions off = TestOptions();
  off.enabled = false;
  EXPECT_EQ(RemoveInconsistentFaces(Photos(), scene.mesh, off).mesh.faces.size(),
            scene.mesh.faces.size());
  EXPECT_EQ(RemoveInconsistentFaces({Photo(0)}, scene.mesh, TestOptions()).num_removed,
            0u);
  // A face no pair sees often enough is not judged, hence kept.
  FaceConsistencyOptions strict = TestOptions();
  strict.min_samples = 1000000;
  const FaceConsistencyResult r = RemoveInconsistentFaces(Photos(), scene.mesh, strict);
  EXPECT_EQ(r.num_removed, 0u);
  EXPECT_EQ(r.num_judged, 0u);
}

TEST(FaceConsistency, NonFiniteVerticesAndBadInput) {
  WallScene scene = WallWithFalseSurface();
  scene.mesh.vertices[0].x() = std::numeric_limits<double>::quiet_NaN();
  scene.mesh.vertices.back().z() = std::numeric_limits<double>::infinity();
  const FaceDifferences d = MeasureFaceDifferences(Photos(), scene.mesh, TestOptions());
  for (const double v : d.mean_difference) EXPECT_TRUE(std::isfinite(v));
  const FaceConsistencyResult r =
      RemoveInconsistentFaces(Photos(), scene.mesh, TestOptions());
  EXPECT_EQ(r.mesh.faces.front(), scene.mesh.faces.front());  // skipped, hence kept

  std::vector<FaceConsistencyView> grey = Photos();
  grey[1].photo = Image(128, 96, 1);
  EXPECT_THROW(RemoveInconsistentFaces(grey, scene.mesh, TestOptions()), Error);
  FaceConsistencyOptions bad = TestOptions();
  bad.depth_tolerance = 0;
  EXPECT_THROW(bad.Check(), Error);
  bad = TestOptions();
  bad.max_colour_difference = std::nan("");
  EXPECT_THROW(bad.Check(), Error);
  bad = TestOptions();
  bad.num_neighbors = 0;
  EXPECT_THROW(bad.Check(), Error);
  EXPECT_NE(TestOptions().ToString(), bad.ToString());
  FaceConsistencyOptions other = TestOptions();
  other.max_colour_difference = 0.2;
  EXPECT_NE(other.ToString(), TestOptions().ToString());
  other.enabled = false;
  EXPECT_EQ(other.ToString(), "consistency=0");
}

}  // namespace
}  // namespace fvs::mvs
