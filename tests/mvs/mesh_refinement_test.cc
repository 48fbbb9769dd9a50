// Mesh refinement by photo-consistency (mvs/mesh_refinement.h) on a generated world with
// exact geometry: a textured wall seen by an arc of cameras. A proxy a few pixels off the
// wall is moved onto it, an exact proxy stays, textureless photos move nothing, and the
// degenerate cases (one photo, a scene 10 km out, bad options) give a valid result or one
// clear error, never a non-finite vertex.
#include "fvs/mvs/mesh_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "fvs/geometry/look_at.h"
#include "fvs/geometry/rasterizer.h"
#include "fvs/util/error.h"

namespace fvs::mvs {
namespace {

constexpr double kWallY = 2.0;
constexpr int kWidth = 192;
constexpr int kHeight = 144;

// A grid in the plane y = wall_y over x in [-2, 2], z in [0, 3], facing the cameras (-y).
// Colours are a hash of the grid cell at a 0.02 spacing: a random texture of about a
// pixel at the photos' size, the same wherever the grid is sampled.
TriangleMesh Wall(double wall_y, double cell, const Eigen::Vector3d& offset) {
  TriangleMesh mesh;
  const int nu = static_cast<int>(std::lround(4.0 / cell));
  const int nv = static_cast<int>(std::lround(3.0 / cell));
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double x = -2 + 4.0 * i / nu, z = 3.0 * j / nv;
      mesh.vertices.push_back(Eigen::Vector3d(x, wall_y, z) + offset);
      uint32_t h = static_cast<uint32_t>(std::lround((x + 2) / 0.02)) * 73856093u ^
                   static_cast<uint32_t>(std::lround(z / 0.02)) * 19349663u;
      h = (h ^ (h >> 13)) * 0x5bd1e995u;
      const uint8_t grey = static_cast<uint8_t>(h >> 24);
      mesh.colors.push_back(Vector3ub(grey, grey, grey));
    }
  }
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int a = j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
      mesh.faces.emplace_back(a, d, b);  // counter-clockwise seen from -y
      mesh.faces.emplace_back(a, c, d);
    }
  }
  return mesh;
}

std::vector<MeshRefinementView> Photos(const TriangleMesh& truth, int n,
                                       const Eigen::Vector3d& offset) {
  std::vector<MeshRefinementView> views;
  RasterizeOptions raster;
  raster.compute_color = true;
  for (int i = 0; i < n; ++i) {
    const double x = -0.8 + 1.6 * i / std::max(1, n - 1);
    const PinholeCamera camera = LookAtCamera(Eigen::Vector3d(x, -2, 1.5) + offset,
                                              Eigen::Vector3d(0, kWallY, 1.5) + offset,
                                              kWidth, kHeight, 0.8 * kWidth);
    views.push_back({camera, Rasterize(truth, camera, raster).color});
  }
  return views;
}

// Mean distance of the vertices the cameras look at (the wall's middle) to the wall.
double MeanWallError(const TriangleMesh& mesh, const Eigen::Vector3d& offset) {
  double sum = 0;
  int count = 0;
  for (const Eigen::Vector3d& world : mesh.vertices) {
    EXPECT_TRUE(world.allFinite());
    const Eigen::Vector3d v = world - offset;
    if (std::abs(v.x()) > 1.0 || std::abs(v.z() - 1.5) > 0.8) continue;
    sum += std::abs(v.y() - kWallY);
    ++count;
  }
  return count > 0 ? sum / count : 0;
}

MeshRefinementOptions SmallOptions() {
  MeshRefinementOptions o;
  o.max_image_size = kWidth;
  return o;
}

TEST(MeshRefinementTest, MovesAProxyAFewPixelsOffOntoTheWall) {
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const auto photos = Photos(Wall(kWallY, 0.02, origin), 6, origin);
  // 0.15 in front of the wall: about 2 pixels of disparity between the outer photos.
  const TriangleMesh proxy = Wall(kWallY - 0.15, 0.1, origin);
  const MeshRefinementResult result = RefineMesh(photos, proxy, SmallOptions());
  const double before = MeanWallError(proxy, origin);
  const double after = MeanWallError(result.mesh, origin);
  EXPECT_NEAR(before, 0.15, 1e-9);
  EXPECT_LT(after, 0.2 * before) << result.Summary();
  EXPECT_EQ(result.mesh.faces, proxy.faces);
  EXPECT_GT(result.last_data_share, 0.3) << result.Summary();
  EXPECT_GT(result.ncc_after, result.ncc_before + 0.05) << result.Summary();
  EXPECT_FALSE(result.stopped_at_time_bound);
}

TEST(MeshRefinementTest, SubdividesACoarseProxyAndStillMovesItOntoTheWall) {
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const auto photos = Photos(Wall(kWallY, 0.02, origin), 6, origin);
  const TriangleMesh proxy = Wall(kWallY - 0.15, 0.4, origin);
  MeshRefinementOptions options = SmallOptions();
  options.max_edge_pixels = 8;
  const MeshRefinementResult result = RefineMesh(photos, proxy, options);
  EXPECT_GT(result.num_vertices_added, 4 * proxy.vertices.size()) << result.Summary();
  EXPECT_EQ(result.mesh.colors.size(), result.mesh.vertices.size());
  EXPECT_LT(MeanWallError(result.mesh, origin), 0.2 * 0.15) << result.Summary();
  options.max_vertices = static_cast<int>(proxy.vertices.size());
  EXPECT_EQ(RefineMesh(photos, proxy, options).num_vertices_added, 0u);
}

TEST(MeshRefinementTest, AnExactProxyStaysOnTheWall) {
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const auto photos = Photos(Wall(kWallY, 0.02, origin), 6, origin);
  const TriangleMesh proxy = Wall(kWallY, 0.1, origin);
  const MeshRefinementResult result = RefineMesh(photos, proxy, SmallOptions());
  // Within half a step of the finest level (a quarter of a pixel's footprint, 0.005).
  EXPECT_LT(MeanWallError(result.mesh, origin), 0.01) << result.Summary();
}

TEST(MeshRefinementTest, TexturelessPhotosMoveNothing) {
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  auto photos = Photos(Wall(kWallY, 0.02, origin), 4, origin);
  for (MeshRefinementView& v : photos)
    std::fill(v.photo.data.begin(), v.photo.data.end(), 0.5f);
  const TriangleMesh proxy = Wall(kWallY - 0.15, 0.1, origin);
  const MeshRefinementResult result = RefineMesh(photos, proxy, SmallOptions());
  EXPECT_EQ(result.mesh.vertices, proxy.vertices);
  EXPECT_EQ(result.last_data_share, 0);
  EXPECT_EQ(result.median_move_pixels, 0);
}

TEST(MeshRefinementTest, WorksTenKilometresFromTheOrigin) {
  const Eigen::Vector3d offset(1e4, -1e4, 30);
  const auto photos = Photos(Wall(kWallY, 0.02, offset), 6, offset);
  const TriangleMesh proxy = Wall(kWallY - 0.15, 0.1, offset);
  const MeshRefinementResult result = RefineMesh(photos, proxy, SmallOptions());
  EXPECT_LT(MeanWallError(result.mesh, offset), 0.2 * 0.15) << result.Summary();
}

TEST(MeshRefinementTest, OnePhotoOrNoFacesLeaveTheMeshAsItIs) {
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const auto photos = Photos(Wall(kWallY, 0.02, origin), 1, origin);
  const TriangleMesh proxy = Wall(kWallY - 0.15, 0.1, origin);
  EXPECT_EQ(RefineMesh(photos, proxy, SmallOptions()).mesh.vertices, proxy.vertices);
  const auto two = Photos(Wall(kWallY, 0.02, origin), 2, origin);
  EXPECT_TRUE(RefineMesh(two, TriangleMesh(), SmallOptions()).mesh.vertices.empty());
}

TEST(MeshRefinementTest, BadOptionsAreRejectedWithTheirName) {
  MeshRefinementOptions o;
  o.patch_size = 6;
  try {
    o.Check();
    FAIL() << "an even patch size was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--Refine.patch_size"), std::string::npos);
  }
  o = MeshRefinementOptions();
  o.max_seconds = std::nan("");
  EXPECT_THROW(o.Check(), Error);
  o = MeshRefinementOptions();
  o.smoothness = -1;
  EXPECT_THROW(o.Check(), Error);
}

}  // namespace
}  // namespace fvs::mvs
