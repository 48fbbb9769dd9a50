// The Delaunay graph-cut mesher against analytic scenes (a room with objects seen from
// inside, objects seen from outside): accuracy, completeness, orientation, outliers,
// far-from-origin coordinates, bad input. Scenes are small so that the whole file runs in
// seconds on 2 cores.
#include "fvs/mvs/delaunay.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <vector>

#ifdef FVS_HAVE_CGAL

#include "colmap_ext/dense_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/ply.h"
#include "fvs/mvs/delaunay_scene.h"
#include "fvs/mvs/isolated_points.h"
#include "fvs/util/error.h"
#include "support/pinhole_model.h"
#include "support/test_support.h"

namespace fvs::mvs {
namespace {

constexpr double kNoise = 0.01;  // 1 cm on a 10 m room: the noise of a good MVS depth map

DelaunayMeshingOptions TestOptions() {
  DelaunayMeshingOptions options;
  options.num_threads = 2;
  return options;
}

// Fraction of faces whose outward normal points into empty space: the face centroid moved
// by `step` along the normal is free, moved against it is not.
double FractionOutward(const MeshingScene& scene, const TriangleMesh& mesh, double step) {
  size_t good = 0;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]], b = mesh.vertices[f[1]],
                          c = mesh.vertices[f[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const Eigen::Vector3d m = (a + b + c) / 3.0;
    good += scene.IsFree(m + step * n) && !scene.IsFree(m - step * n);
  }
  return mesh.faces.empty() ? 0 : static_cast<double>(good) / mesh.faces.size();
}

void ExpectAccurate(const MeshAccuracy& acc, const char* what) {
  SCOPED_TRACE(what);
  // Mesh vertices are input points: for inliers the distance to the surface is |N(0, s)|
  // along the normal (mean 0.8 s, 90th percentile 1.64 s). Twice that, plus a little for
  // the few outliers that end up on the surface, bounds a mesher that keeps the surface
  // and drops the outliers; a mesh pulled towards outliers or with spurious faces fails.
  EXPECT_LT(acc.vertex_mean, 2 * kNoise);
  EXPECT_LT(acc.vertex_p90, 3 * kNoise);
  // Points on faces also see the triangles' curvature error on the sphere and at corners.
  EXPECT_LT(acc.face_mean, 2 * kNoise);
  EXPECT_LT(acc.face_p90, 3.5 * kNoise);
  // Every visible part of the true surface is meshed: 5 noise sigmas is far beyond the
  // noise.
  EXPECT_GT(acc.coverage, 0.95);
}

TEST(DelaunayMesher, RoomWithObjectsSeenFromInside) {
  const MeshingScene scene = MakeRoomScene(12);
  const SampledCloud cloud = SampleScene(scene, 40000, kNoise, 0.05, 1);
  DelaunayMeshingStats stats;
  const TriangleMesh mesh = DelaunayMeshing(cloud.input, TestOptions(), &stats);
  std::printf("room: %s\n", stats.Summary().c_str());
  ASSERT_GT(mesh.faces.size(), 1000u);
  const MeshAccuracy acc = EvaluateMesh(scene, mesh, cloud.true_points, 5 * kNoise);
  std::printf("room: vertex mean %.4f p90 %.4f, face mean %.4f p90 %.4f, coverage %.3f\n",
              acc.vertex_mean, acc.vertex_p90, acc.face_mean, acc.face_p90, acc.coverage);
  ExpectAccurate(acc, "room");
  EXPECT_GT(FractionOutward(scene, mesh, 0.03), 0.95);
  for (const auto& v : mesh.vertices) ASSERT_TRUE(v.allFinite());
  for (const auto& f : mesh.faces) {
    for (int j = 0; j < 3; ++j) {
      ASSERT_GE(f[j], 0);
      ASSERT_LT(f[j], static_cast<int>(mesh.vertices.size()));
    }
  }
}

TEST(DelaunayMesher, ObjectsSeenFromOutside) {
  const MeshingScene scene = MakeObjectScene(12);
  const SampledCloud cloud = SampleScene(scene, 30000, kNoise, 0.05, 2);
  DelaunayMeshingStats stats;
  const TriangleMesh mesh = DelaunayMeshing(cloud.input, TestOptions(), &stats);
  std::printf("objects: %s\n", stats.Summary().c_str());
  ASSERT_GT(mesh.faces.size(), 1000u);
  const MeshAccuracy acc = EvaluateMesh(scene, mesh, cloud.true_points, 5 * kNoise);
  std::printf(
      "objects: vertex mean %.4f p90 %.4f, face mean %.4f p90 %.4f, coverage %.3f\n",
      acc.vertex_mean, acc.vertex_p90, acc.face_mean, acc.face_p90, acc.coverage);
  ExpectAccurate(acc, "objects");
  EXPECT_GT(FractionOutward(scene, mesh, 0.03), 0.95);
}

TEST(DelaunayMesher, ToleratesManyOutliers) {
  // A quarter of the points are outliers seen by two images each: their rays carry little
  // weight (1 - exp(-4/18) = 0.2 against 0.75 for a point seen 5 times) and the free
  // space carved by the inliers' rays removes them.
  const MeshingScene scene = MakeRoomScene(12);
  const SampledCloud cloud = SampleScene(scene, 40000, kNoise, 0.25, 3);
  ASSERT_GT(cloud.num_outliers, 9000u);
  const TriangleMesh mesh = DelaunayMeshing(cloud.input, TestOptions());
  const MeshAccuracy acc = EvaluateMesh(scene, mesh, cloud.true_points, 5 * kNoise);
  std::printf(
      "outliers: vertex mean %.4f p90 %.4f, face mean %.4f p90 %.4f, coverage %.3f\n",
      acc.vertex_mean, acc.vertex_p90, acc.face_mean, acc.face_p90, acc.coverage);
  ExpectAccurate(acc, "25% outliers");
}

TEST(IsolatedPoints, FlagsOnlyPointsFarFromTheRest) {
  // A 30 x 30 grid of 1 cm spacing, and three points 1 m away from it and each other.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) points.emplace_back(0.01 * i, 0.01 * j, 0.0);
  }
  const size_t first_stray = points.size();
  points.emplace_back(1.5, 0.1, 0.3);
  points.emplace_back(0.1, 1.4, -0.6);
  points.emplace_back(-1.0, -1.0, 1.0);
  const std::vector<double> spacing = MeanNeighborDistances(points, 4, 2);
  EXPECT_NEAR(spacing[31], (0.01 * 4 + 0.0) / 4, 1e-12);  // 4 neighbours at 1 cm
  IsolatedPointOptions options;
  const std::vector<bool> isolated = FindIsolatedPoints(points, options);
  for (size_t i = 0; i < points.size(); ++i)
    EXPECT_EQ(isolated[i], i >= first_stray) << i;
  // Far from the origin: the same answer.
  for (auto& p : points) p += Eigen::Vector3d(3e4, -1e4, 2e3);
  EXPECT_EQ(FindIsolatedPoints(points, options), isolated);
  options.num_neighbors = 0;
  const std::vector<bool> none = FindIsolatedPoints(points, options);
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
  options.num_neighbors = 8;
  options.factor = 0.5;
  EXPECT_THROW(options.Check(), Error);
}

TEST(DelaunayMesher, StrayPointsAnchorNoFaces) {
  // Clusters of 3 points in the empty space around the objects, each seen by 5 cameras
  // (as fused background noise is): with the default filters no face reaches them and the
  // accuracy of the rest is unchanged; without them (COLMAP's behaviour) faces do.
  const MeshingScene scene = MakeObjectScene(12);
  SampledCloud cloud = SampleScene(scene, 20000, kNoise, 0.0, 6);
  Eigen::Vector3d lo = cloud.input.points[0], hi = lo;
  for (const auto& p : cloud.input.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d size = hi - lo;
  std::vector<Eigen::Vector3d> strays;
  for (int c = 0; c < 6; ++c) {
    const Eigen::Vector3d centre =
        lo + size.cwiseProduct(Eigen::Vector3d(c % 2 ? -0.25 : 1.25, 0.2 + 0.12 * c,
                                               c % 3 ? 1.2 : -0.2));
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d p =
          centre + Eigen::Vector3d(0.004 * j, -0.003 * j, 0.002 * j);
      strays.push_back(p);
      cloud.input.points.push_back(p);
      cloud.input.visibility.push_back({0, 2, 4, 6, 8});
    }
  }
  auto touches_stray = [&](const TriangleMesh& mesh) {
    size_t n = 0;
    for (const auto& f : mesh.faces) {
      for (int j = 0; j < 3; ++j) {
        for (const auto& s : strays) n += (mesh.vertices[f[j]] - s).norm() < 1e-9;
      }
    }
    return n;
  };
  DelaunayMeshingStats stats;
  const TriangleMesh filtered = DelaunayMeshing(cloud.input, TestOptions(), &stats);
  std::printf("strays: %s\n", stats.Summary().c_str());
  EXPECT_GE(stats.num_isolated_points, strays.size());
  EXPECT_EQ(touches_stray(filtered), 0u);
  ExpectAccurate(EvaluateMesh(scene, filtered, cloud.true_points, 5 * kNoise), "strays");
  DelaunayMeshingOptions colmap_like = TestOptions();
  colmap_like.isolated_point_neighbors = 0;
  colmap_like.max_side_spacing_factor = 0;
  const TriangleMesh unfiltered = DelaunayMeshing(cloud.input, colmap_like);
  const size_t unfiltered_touching = touches_stray(unfiltered);
  std::printf("strays, unfiltered: %zu faces touch them\n", unfiltered_touching);
  EXPECT_GT(unfiltered_touching, 0u);  // the case the filters are for
}

TEST(DelaunayMesher, FarFromOriginMeshesAsAtOrigin) {
  const MeshingScene scene = MakeObjectScene(10);
  SampledCloud cloud = SampleScene(scene, 15000, kNoise, 0.0, 4);
  const TriangleMesh near_mesh = DelaunayMeshing(cloud.input, TestOptions());
  // 10 km away: float coordinates would have 1 mm steps, the centred doubles are exact.
  const Eigen::Vector3d shift(1e4, -2e4, 5e3);
  for (auto& p : cloud.input.points) p += shift;
  for (auto& camera : cloud.input.cameras) camera.t -= camera.R * shift;
  const TriangleMesh far_mesh = DelaunayMeshing(cloud.input, TestOptions());
  ASSERT_GT(near_mesh.faces.size(), 1000u);
  const double ratio = static_cast<double>(far_mesh.faces.size()) /
                       static_cast<double>(near_mesh.faces.size());
  EXPECT_NEAR(ratio, 1.0, 0.01);
  MeshingScene shifted = scene;
  for (auto& prim : shifted.primitives) prim.centre += shift;
  std::vector<Eigen::Vector3d> true_points = cloud.true_points;
  for (auto& p : true_points) p += shift;
  ExpectAccurate(EvaluateMesh(shifted, far_mesh, true_points, 5 * kNoise), "far");
}

TEST(DelaunayMesher, MergingPointsKeepsAccuracy) {
  // max_proj_dist = 0 (every point a vertex) and the default 20 px merge mesh the same
  // surface; merging gives fewer vertices.
  const MeshingScene scene = MakeObjectScene(12, 160, 120);
  const SampledCloud cloud = SampleScene(scene, 20000, kNoise, 0.02, 5);
  DelaunayMeshingOptions options = TestOptions();
  options.max_proj_dist = 0;
  DelaunayMeshingStats all_stats, merged_stats;
  const TriangleMesh all = DelaunayMeshing(cloud.input, options, &all_stats);
  options.max_proj_dist = 3;
  const TriangleMesh merged = DelaunayMeshing(cloud.input, options, &merged_stats);
  std::printf("no merge: %s\nmerge 3 px: %s\n", all_stats.Summary().c_str(),
              merged_stats.Summary().c_str());
  EXPECT_LT(merged_stats.num_vertices, all_stats.num_vertices);
  EXPECT_GT(all_stats.num_vertices, 19000u);  // outliers and inliers, few duplicates
  const MeshAccuracy a = EvaluateMesh(scene, all, cloud.true_points, 5 * kNoise);
  const MeshAccuracy m = EvaluateMesh(scene, merged, cloud.true_points, 5 * kNoise);
  ExpectAccurate(a, "no merge");
  EXPECT_LT(m.vertex_mean, 2 * kNoise);
  EXPECT_GT(m.coverage, 0.9);
}

TEST(DelaunayMesher, DegenerateCloudsAreRejected) {
  DelaunayMeshingInput input;
  input.cameras.push_back(LookAtCamera({0.5, -5, 5}, {0.5, 0.5, 0}, 100, 100, 80));
  // All points on the plane z = 0.
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      input.points.emplace_back(i * 0.1, j * 0.1, 0.0);
      input.visibility.push_back({0});
    }
  }
  try {
    DelaunayMeshing(input, TestOptions());
    FAIL() << "coplanar cloud accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate"), std::string::npos) << e.what();
  }
  // Collinear.
  input.points.clear();
  input.visibility.clear();
  for (int i = 0; i < 30; ++i) {
    input.points.emplace_back(i * 0.1, 0.0, 0.0);
    input.visibility.push_back({0});
  }
  EXPECT_THROW(DelaunayMeshing(input, TestOptions()), Error);
  // Too few points, no points.
  input.points.resize(3);
  input.visibility.resize(3);
  EXPECT_THROW(DelaunayMeshing(input, TestOptions()), Error);
  input.points.clear();
  input.visibility.clear();
  EXPECT_THROW(DelaunayMeshing(input, TestOptions()), Error);
}

TEST(DelaunayMesher, BadInputAndOptionsAreRejected) {
  const MeshingScene scene = MakeObjectScene(6, 80, 60);
  SampledCloud cloud = SampleScene(scene, 500, kNoise, 0.0, 6);
  DelaunayMeshingInput bad = cloud.input;
  bad.visibility.pop_back();
  EXPECT_THROW(DelaunayMeshing(bad, TestOptions()), Error);
  bad = cloud.input;
  bad.visibility[10].push_back(99);  // no image 99
  EXPECT_THROW(DelaunayMeshing(bad, TestOptions()), Error);
  bad = cloud.input;
  bad.points[3].x() = std::nan("");
  EXPECT_THROW(DelaunayMeshing(bad, TestOptions()), Error);
  DelaunayMeshingOptions options = TestOptions();
  options.max_depth_dist = 2;
  EXPECT_THROW(DelaunayMeshing(cloud.input, options), Error);
  options = TestOptions();
  options.visibility_sigma = 0;
  EXPECT_THROW(options.Check(), Error);
  options = TestOptions();
  options.max_side_length_percentile = 101;
  EXPECT_THROW(options.Check(), Error);
  options = TestOptions();
  options.quality_regularization = -1;
  EXPECT_THROW(options.Check(), Error);
  EXPECT_NO_THROW(TestOptions().Check());
}

// prepare's meshing fingerprint: "" for the defaults before session 29 (the fingerprint
// of the meshes made then), something else for today's defaults (so those meshes are made
// again), and every option that shapes the mesh changes it.
TEST(DelaunayMesher, OptionsStringNamesWhatShapesTheMesh) {
  DelaunayMeshingOptions legacy;
  legacy.max_proj_dist = 20;
  legacy.max_side_spacing_factor = 10;
  EXPECT_EQ(legacy.ToString(), "");
  legacy.num_threads = 1;
  EXPECT_EQ(legacy.ToString(), "");
  EXPECT_NE(DelaunayMeshingOptions().ToString(), "");
  const std::vector<std::function<void(DelaunayMeshingOptions*)>> changes = {
      [](DelaunayMeshingOptions* o) { o->max_proj_dist = 5; },
      [](DelaunayMeshingOptions* o) { o->max_depth_dist = 0.01; },
      [](DelaunayMeshingOptions* o) { o->visibility_sigma = 2; },
      [](DelaunayMeshingOptions* o) { o->distance_sigma_factor = 2; },
      [](DelaunayMeshingOptions* o) { o->quality_regularization = 0.5; },
      [](DelaunayMeshingOptions* o) { o->max_side_length_factor = 10; },
      [](DelaunayMeshingOptions* o) { o->max_side_length_percentile = 90; },
      [](DelaunayMeshingOptions* o) { o->isolated_point_neighbors = 0; },
      [](DelaunayMeshingOptions* o) { o->isolated_point_factor = 3; },
      [](DelaunayMeshingOptions* o) { o->max_side_spacing_factor = 0; },
      [](DelaunayMeshingOptions* o) { o->sparse_min_track_length = 3; },
      [](DelaunayMeshingOptions* o) { o->sparse_max_error = 1; }};
  std::set<std::string> seen;
  for (const auto& change : changes) {
    DelaunayMeshingOptions o = legacy;
    change(&o);
    EXPECT_NE(o.ToString(), "");
    seen.insert(o.ToString());
  }
  EXPECT_EQ(seen.size(), changes.size());
}

// --- The dense workspace: fused.ply + fused.ply.vis + sparse/ -> meshed-delaunay.ply ---

void WriteWorkspace(const std::string& dir, const DelaunayMeshingInput& input) {
  std::filesystem::create_directories(dir + "/sparse");
  PointCloud cloud;
  cloud.points = input.points;
  WritePlyPointCloud(dir + "/fused.ply", cloud);
  colmap::WriteFusedVisibility(dir + "/fused.ply.vis", input.visibility);
  colmap::Reconstruction reconstruction;
  for (size_t k = 0; k < input.cameras.size(); ++k) {
    testing::AddPinholeImage(input.cameras[k], "image" + std::to_string(k) + ".png",
                             &reconstruction);
  }
  colmap::WriteSparseModelBinary(dir + "/sparse", reconstruction);
}

TEST(DelaunayMesherWorkspace, WritesMeshedDelaunayPly) {
  testing::TempDir dir;
  const MeshingScene scene = MakeObjectScene(10);
  const SampledCloud cloud = SampleScene(scene, 15000, kNoise, 0.05, 7);
  WriteWorkspace(dir.path(), cloud.input);
  const std::string out = dir / "meshed-delaunay.ply";
  const DelaunayMeshingStats stats = DenseDelaunayMeshing(dir.path(), out, TestOptions());
  const TriangleMesh mesh = ReadPlyMesh(out);
  EXPECT_EQ(mesh.faces.size(), stats.num_faces);
  EXPECT_EQ(mesh.vertices.size(), stats.num_mesh_vertices);
  // Written as float (COLMAP's format): 1e-6 relative rounding is far below the noise.
  ExpectAccurate(EvaluateMesh(scene, mesh, cloud.true_points, 5 * kNoise), "workspace");
  // No temporary files left beside the output.
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 4u);  // sparse/, fused.ply, fused.ply.vis, meshed-delaunay.ply
}

TEST(DelaunayMesherWorkspace, BadWorkspacesFailWithoutOutput) {
  const MeshingScene scene = MakeObjectScene(6, 80, 60);
  const SampledCloud cloud = SampleScene(scene, 2000, kNoise, 0.0, 8);
  auto expect_error = [](const std::string& ws, const std::string& needle) {
    const std::string out = ws + "/meshed-delaunay.ply";
    try {
      DenseDelaunayMeshing(ws, out, TestOptions());
      ADD_FAILURE() << "no error for " << needle;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    }
    EXPECT_FALSE(std::filesystem::exists(out));
  };
  {  // Empty fused cloud.
    testing::TempDir dir;
    DelaunayMeshingInput empty = cloud.input;
    empty.points.clear();
    empty.visibility.clear();
    WriteWorkspace(dir.path(), empty);
    expect_error(dir.path(), "empty point cloud");
  }
  {  // A vis file of another cloud (count differs).
    testing::TempDir dir;
    WriteWorkspace(dir.path(), cloud.input);
    auto vis = cloud.input.visibility;
    vis.resize(vis.size() - 7);
    colmap::WriteFusedVisibility(dir / "fused.ply.vis", vis);
    expect_error(dir.path(), "do not belong together");
  }
  {  // A vis file naming images the sparse model does not have.
    testing::TempDir dir;
    WriteWorkspace(dir.path(), cloud.input);
    auto vis = cloud.input.visibility;
    vis[5] = {0, 6};
    colmap::WriteFusedVisibility(dir / "fused.ply.vis", vis);
    expect_error(dir.path(), "image index 6");
  }
  {  // No vis file at all.
    testing::TempDir dir;
    WriteWorkspace(dir.path(), cloud.input);
    std::filesystem::remove(dir / "fused.ply.vis");
    expect_error(dir.path(), "fused.ply.vis");
  }
  {  // Coplanar points: no volume, no mesh.
    testing::TempDir dir;
    DelaunayMeshingInput flat = cloud.input;
    for (auto& p : flat.points) p.z() = 0.25;
    WriteWorkspace(dir.path(), flat);
    expect_error(dir.path(), "degenerate");
  }
}

TEST(DelaunayMesherCommand, RunsThroughTheFrontDoor) {
  const std::string colmap = testing::FrontDoorBinary();
  if (!std::filesystem::exists(colmap)) GTEST_SKIP() << colmap << " not built";
  testing::TempDir dir;
  const MeshingScene scene = MakeObjectScene(8, 160, 120);
  const SampledCloud cloud = SampleScene(scene, 8000, kNoise, 0.02, 9);
  WriteWorkspace(dir.path(), cloud.input);
  std::string output;
  const std::string base = "FVS_QUIET=1 " + colmap +
                           " view_synthesis_mesher --workspace_path " + dir.path() +
                           " --DelaunayMeshing.num_threads 2";
  ASSERT_EQ(testing::RunShell(base, &output), 0) << output;
  const TriangleMesh mesh = ReadPlyMesh(dir / "meshed-delaunay.ply");
  EXPECT_GT(mesh.faces.size(), 1000u);
  EXPECT_LT(EvaluateMesh(scene, mesh, cloud.true_points, 5 * kNoise).face_mean,
            2 * kNoise);
  // Options with COLMAP's names; a bad value is one error line and exit code 1.
  EXPECT_EQ(testing::RunShell(base + " --DelaunayMeshing.max_depth_dist 2", &output), 1);
  EXPECT_NE(output.find("max_depth_dist"), std::string::npos) << output;
  // A vis file that does not belong to the cloud: error, and the old output is untouched.
  std::filesystem::remove(dir / "meshed-delaunay.ply");
  colmap::WriteFusedVisibility(dir / "fused.ply.vis", {{0, 1}, {1, 2}});
  EXPECT_EQ(testing::RunShell(base, &output), 1);
  EXPECT_NE(output.find("do not belong together"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(dir / "meshed-delaunay.ply"));
}

TEST(DelaunayMesherWorkspace, VisibilityIndicesFollowImageFileOrder) {
  // COLMAP 3.8 numbers images by their position in images.bin/.txt, not by id.
  testing::TempDir dir;
  testing::WriteTextFile(dir / "images.txt",
                         "# Image list with two lines of data per image:\n"
                         "7 1 0 0 0 0 0 0 1 b.png\n"
                         "\n"
                         "3 1 0 0 0 0 0 0 1 a.png\n"
                         "1.5 2.5 -1\n"
                         "5 1 0 0 0 0 0 0 1 c.png\n"
                         "\n");
  EXPECT_EQ(ReadImageIdsInFileOrder(dir.path()), (std::vector<uint32_t>{7, 3, 5}));
  {
    std::ofstream bin(dir / "images.bin", std::ios::binary);
    const uint64_t count = 2;
    bin.write(reinterpret_cast<const char*>(&count), 8);
    for (const uint32_t id : {9u, 2u}) {
      bin.write(reinterpret_cast<const char*>(&id), 4);
      const double pose[7] = {1, 0, 0, 0, 0, 0, 0};
      bin.write(reinterpret_cast<const char*>(pose), sizeof(pose));
      const uint32_t camera_id = 1;
      bin.write(reinterpret_cast<const char*>(&camera_id), 4);
      bin.write("x.png", 6);  // with its '\0'
      const uint64_t num_points = id == 9 ? 1 : 0;
      bin.write(reinterpret_cast<const char*>(&num_points), 8);
      if (num_points) {
        const double xy[2] = {1, 2};
        const uint64_t point_id = 4;
        bin.write(reinterpret_cast<const char*>(xy), 16);
        bin.write(reinterpret_cast<const char*>(&point_id), 8);
      }
    }
  }
  EXPECT_EQ(ReadImageIdsInFileOrder(dir.path()), (std::vector<uint32_t>{9, 2}));
  std::filesystem::resize_file(dir / "images.bin", 30);
  EXPECT_THROW(ReadImageIdsInFileOrder(dir.path()), Error);
}

}  // namespace
}  // namespace fvs::mvs

#else  // !FVS_HAVE_CGAL

TEST(DelaunayMesher, NotBuilt) {
  static_assert(!fvs::mvs::DelaunayMesherAvailable());
  GTEST_SKIP()
      << "built without CGAL or Boost.Graph: the Delaunay mesher is not available";
}

#endif
