// SfM points in the mesher (DelaunayMeshingOptions::sparse_min_track_length): which SfM
// points the dense-workspace reader admits (track length over the fused images of
// stereo/fusion.cfg, reprojection error), and that they give a surface where stereo left
// none (a room whose walls fusion missed) without spoiling what fusion found.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "fvs/mvs/delaunay.h"

#ifdef FVS_HAVE_CGAL

#include "colmap_ext/dense_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/ply.h"
#include "fvs/mvs/delaunay_scene.h"
#include "support/pinhole_model.h"
#include "support/test_support.h"

namespace fvs::mvs {
namespace {

struct SfmPoint {
  Eigen::Vector3d xyz;
  std::vector<uint32_t> track;  // camera indices (image id = index + 1)
  double error = 0.5;
};

// fused.ply(.vis) of `fused`, sparse/ with `cameras` and `sfm`, and stereo/fusion.cfg
// listing every image except those in `held_out`.
void WriteWorkspace(const std::string& dir, const DelaunayMeshingInput& fused,
                    const std::vector<SfmPoint>& sfm, const std::set<size_t>& held_out) {
  namespace fs = std::filesystem;
  fs::create_directories(dir + "/sparse");
  fs::create_directories(dir + "/stereo");
  PointCloud cloud;
  cloud.points = fused.points;
  WritePlyPointCloud(dir + "/fused.ply", cloud);
  colmap::WriteFusedVisibility(dir + "/fused.ply.vis", fused.visibility);
  colmap::Reconstruction reconstruction;
  std::ofstream fusion_cfg(dir + "/stereo/fusion.cfg");
  for (size_t k = 0; k < fused.cameras.size(); ++k) {
    const std::string name = "image" + std::to_string(k) + ".png";
    testing::AddPinholeImage(fused.cameras[k], name, &reconstruction);
    if (!held_out.count(k)) fusion_cfg << name << "\n";
  }
  for (size_t i = 0; i < sfm.size(); ++i) {
    colmap::Point3D point;
    point.xyz = sfm[i].xyz;
    point.error = sfm[i].error;
    for (const uint32_t k : sfm[i].track) {
      colmap::Image& image = reconstruction.images.at(k + 1);
      colmap::Point2D p;
      p.xy = fused.cameras[k].CameraToPixel(fused.cameras[k].WorldToCamera(sfm[i].xyz));
      p.point3D_id = i + 1;
      point.track.push_back({k + 1, static_cast<uint32_t>(image.points2D.size())});
      image.points2D.push_back(p);
    }
    reconstruction.points3D[i + 1] = point;
  }
  colmap::WriteSparseModelBinary(dir + "/sparse", reconstruction);
}

TEST(DelaunayMesherSparse, AdmitsSfmPointsSeenByEnoughFusedImages) {
  const MeshingScene scene = MakeObjectScene(8, 64, 48);
  const SampledCloud cloud = SampleScene(scene, 200, 0.0, 0.0, 3);
  const Eigen::Vector3d a(0.1, 0.2, 0.3), b(0.4, 0.5, 0.6), c(0.7, 0.8, 0.9),
      d(1.0, 1.1, 1.2);
  const std::vector<SfmPoint> sfm = {
      {a, {0, 1, 2}, 0.5},     // three fused images: in
      {b, {0, 1, 7}, 0.5},     // image 7 is held out: two fused images
      {c, {0, 1, 2, 3}, 5.0},  // reprojection error too large
      {d, {4, 4, 5}, 0.5},     // one image twice: two distinct
  };
  testing::TempDir dir;
  WriteWorkspace(dir.path(), cloud.input, sfm, {7});

  DelaunayMeshingOptions options;
  options.sparse_min_track_length = 3;  // error <= 2 px by default
  DelaunayMeshingInput input = ReadDenseMeshingInput(dir.path(), options);
  ASSERT_EQ(input.num_sparse_points, 1u);
  ASSERT_EQ(input.points.size(), cloud.input.points.size() + 1);
  EXPECT_EQ(input.points.back(), a);
  // Visibility indices name the cameras of the track (positions in images.bin order).
  ASSERT_EQ(input.visibility.back().size(), 3u);
  for (size_t j = 0; j < 3; ++j) {
    EXPECT_TRUE(input.cameras[input.visibility.back()[j]].Center().isApprox(
        cloud.input.cameras[j].Center()));
  }

  options = DelaunayMeshingOptions();  // the default: two fused images
  input = ReadDenseMeshingInput(dir.path(), options);
  EXPECT_EQ(input.num_sparse_points, 3u);  // a, b (without image 7), d
  EXPECT_EQ(input.visibility.back().size(), 2u);

  options.sparse_max_error = 10;
  EXPECT_EQ(ReadDenseMeshingInput(dir.path(), options).num_sparse_points, 4u);

  options.sparse_min_track_length = 0;  // COLMAP's input: fused points only
  input = ReadDenseMeshingInput(dir.path(), options);
  EXPECT_EQ(input.num_sparse_points, 0u);
  EXPECT_EQ(input.points.size(), cloud.input.points.size());

  // Without fusion.cfg every registered image counts as fused: b has three.
  std::filesystem::remove(dir / "stereo/fusion.cfg");
  options = DelaunayMeshingOptions();
  options.sparse_min_track_length = 3;
  EXPECT_EQ(ReadDenseMeshingInput(dir.path(), options).num_sparse_points, 2u);

  // A fusion.cfg that cannot be read fails with SfM points and is not read without.
  std::filesystem::create_directory(dir / "stereo/fusion.cfg");
  EXPECT_THROW(ReadDenseMeshingInput(dir.path(), options), Error);
  options.sparse_min_track_length = 0;
  EXPECT_EQ(ReadDenseMeshingInput(dir.path(), options).num_sparse_points, 0u);

  options.sparse_min_track_length = -1;
  EXPECT_THROW(options.Check(), Error);
  options = DelaunayMeshingOptions();
  options.sparse_max_error = 0;
  EXPECT_THROW(options.Check(), Error);
}

// A room whose walls, floor and ceiling stereo did not fuse (textureless), only the
// objects on the floor; SfM has a few points on them.
TEST(DelaunayMesherSparse, SfmPointsMeshWhatFusionMissed) {
  const MeshingScene scene = MakeRoomScene(12, 160, 120);
  const SampledCloud cloud = SampleScene(scene, 30000, 0.01, 0.0, 5);
  MeshingScene objects = scene;  // the solid primitives alone
  objects.primitives.erase(objects.primitives.begin());
  DelaunayMeshingInput fused;
  fused.cameras = cloud.input.cameras;
  std::vector<SfmPoint> sfm;
  std::vector<Eigen::Vector3d> walls;  // true samples of what fusion missed
  for (size_t i = 0; i < cloud.input.points.size(); ++i) {
    const Eigen::Vector3d& p = cloud.true_points[i];
    if (objects.DistanceToSurface(p) < 0.05) {
      fused.points.push_back(cloud.input.points[i]);
      fused.visibility.push_back(cloud.input.visibility[i]);
    } else {
      walls.push_back(p);
      // One in 20 as an SfM point (SfM is sparse), when three images see it.
      if (i % 20 == 0 && cloud.input.visibility[i].size() >= 3) {
        sfm.push_back({cloud.input.points[i], cloud.input.visibility[i], 0.5});
      }
    }
  }
  ASSERT_GT(fused.points.size(), 3000u);
  ASSERT_GT(sfm.size(), 300u);
  testing::TempDir dir;
  WriteWorkspace(dir.path(), fused, sfm, {});

  DelaunayMeshingOptions options;
  options.num_threads = 2;
  auto mesh_with = [&](int min_track, const char* name) {
    options.sparse_min_track_length = min_track;
    const std::string out = dir / (std::string(name) + ".ply");
    const DelaunayMeshingStats stats = DenseDelaunayMeshing(dir.path(), out, options);
    std::printf("%s: %s\n", name, stats.Summary().c_str());
    return ReadPlyMesh(out);
  };
  const TriangleMesh fused_only = mesh_with(0, "fused only");
  const TriangleMesh with_sfm = mesh_with(2, "with SfM points");
  const MeshAccuracy before = EvaluateMesh(scene, fused_only, walls, 0.1);
  const MeshAccuracy after = EvaluateMesh(scene, with_sfm, walls, 0.1);
  std::vector<Eigen::Vector3d> object_points;
  for (const auto& p : cloud.true_points) {
    if (objects.DistanceToSurface(p) < 0.05) object_points.push_back(p);
  }
  const MeshAccuracy objects_before =
      EvaluateMesh(scene, fused_only, object_points, 0.05);
  const MeshAccuracy objects_after = EvaluateMesh(scene, with_sfm, object_points, 0.05);
  std::printf(
      "walls covered: %.3f fused only, %.3f with SfM points (face mean %.4f p90 %.4f); "
      "objects covered %.3f -> %.3f\n",
      before.coverage, after.coverage, after.face_mean, after.face_p90,
      objects_before.coverage, objects_after.coverage);
  EXPECT_LT(before.coverage, 0.3);
  EXPECT_GT(after.coverage, 0.8);
  // The new faces lie on the walls: a face mean within a few noise sigmas.
  EXPECT_LT(after.face_mean, 0.05);
  EXPECT_GT(objects_after.coverage, objects_before.coverage - 0.02);
}

}  // namespace
}  // namespace fvs::mvs

#endif  // FVS_HAVE_CGAL
