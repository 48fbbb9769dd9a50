// The mesher on the output of the real COLMAP: exact depth and normal maps of an analytic
// scene are written into a dense workspace, COLMAP 3.8's stereo_fusion fuses them into
// fused.ply + fused.ply.vis, and the mesher reads those. This pins down what the indices
// in fused.ply.vis mean (positions in the file order of sparse/images.*, not image ids
// and not ids sorted) and that a COLMAP workspace meshes end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "fvs/mvs/delaunay.h"

#ifdef FVS_HAVE_CGAL

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "fvs/geometry/ply.h"
#include "fvs/mvs/delaunay_scene.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs::mvs {
namespace {

// Image ids in the (deliberately unsorted) order of images.txt.
const uint32_t kImageIds[] = {40, 10, 70, 20, 60, 30, 80, 50};

void WriteFusionWorkspace(const std::string& ws, const MeshingScene& scene) {
  namespace fs = std::filesystem;
  fs::create_directories(ws + "/images");
  fs::create_directories(ws + "/sparse");
  fs::create_directories(ws + "/stereo/depth_maps");
  fs::create_directories(ws + "/stereo/normal_maps");
  std::ostringstream cameras, images, fusion_cfg, points3D;
  cameras.precision(17);
  images.precision(17);
  // One sparse point seen by every image: COLMAP's fusion picks the images to check a
  // pixel against by shared sparse points, so without it nothing fuses.
  const Eigen::Vector3d anchor(1.0, 0.15, 0.0);
  points3D << "1 " << anchor.x() << " " << anchor.y() << " " << anchor.z()
           << " 128 128 128 0.5";
  for (size_t k = 0; k < scene.cameras.size(); ++k) {
    const PinholeCamera& c = scene.cameras[k];
    const uint32_t id = kImageIds[k];
    const std::string name = "view" + std::to_string(id) + ".png";
    cameras << id << " PINHOLE " << c.width << " " << c.height << " " << c.fx << " "
            << c.fy << " " << c.cx << " " << c.cy << "\n";
    const Eigen::Vector4d q = RotationToQuaternion(c.R);
    images << id << " " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << " "
           << c.t[0] << " " << c.t[1] << " " << c.t[2] << " " << id << " " << name
           << "\n";
    const Eigen::Vector2d xy = c.CameraToPixel(c.WorldToCamera(anchor));
    images << xy.x() << " " << xy.y() << " 1\n";
    points3D << " " << id << " 0";
    fusion_cfg << name << "\n";
    // Exact depth (camera z) and camera-frame normals (facing the camera) per pixel
    // centre.
    Image depth(c.width, c.height, 1), normals(c.width, c.height, 3),
        colour(c.width, c.height, 3);
    const Eigen::Vector3d centre = c.Center();
    for (int y = 0; y < c.height; ++y) {
      for (int x = 0; x < c.width; ++x) {
        const Eigen::Vector3d dir = c.Unproject(x + 0.5, y + 0.5, 1.0) - centre;
        const double t = scene.FirstHit(centre, dir);
        if (!std::isfinite(t)) continue;
        const Eigen::Vector3d p = centre + t * dir;
        depth.at(x, y) = static_cast<float>(c.WorldToCamera(p).z());
        Eigen::Vector3d n = c.R * scene.NormalAt(p);
        if (n.dot(c.WorldToCamera(p)) > 0) n = -n;
        for (int j = 0; j < 3; ++j) normals.at(x, y, j) = static_cast<float>(n[j]);
        const float g =
            0.5f + 0.4f * static_cast<float>(std::sin(7 * p.x()) * std::cos(5 * p.y()));
        for (int j = 0; j < 3; ++j) colour.at(x, y, j) = g;
      }
    }
    colmap::WriteImage(ws + "/images/" + name, colour);
    colmap::WriteColmapArray(ws + "/stereo/depth_maps/" + name + ".geometric.bin", depth);
    colmap::WriteColmapArray(ws + "/stereo/normal_maps/" + name + ".geometric.bin",
                             normals);
  }
  testing::WriteTextFile(ws + "/sparse/cameras.txt", cameras.str());
  testing::WriteTextFile(ws + "/sparse/images.txt", images.str());
  testing::WriteTextFile(ws + "/sparse/points3D.txt", points3D.str() + "\n");
  testing::WriteTextFile(ws + "/stereo/fusion.cfg", fusion_cfg.str());
}

// Fraction of (point, listed camera) pairs where the camera really sees the point.
double FractionConsistent(const MeshingScene& scene, const DelaunayMeshingInput& input) {
  size_t good = 0, total = 0;
  for (size_t i = 0; i < input.points.size(); ++i) {
    for (const uint32_t k : input.visibility[i]) {
      ++total;
      const PinholeCamera& c = input.cameras[k];
      const Eigen::Vector3d pc = c.WorldToCamera(input.points[i]);
      if (pc.z() <= 0) continue;
      const Eigen::Vector3d centre = c.Center();
      const double t = scene.FirstHit(centre, input.points[i] - centre);
      const Eigen::Vector2d px = c.CameraToPixel(pc);
      good += px.x() >= 0 && px.y() >= 0 && px.x() < c.width && px.y() < c.height &&
              std::abs(t - 1.0) < 0.01;
    }
  }
  return total ? static_cast<double>(good) / total : 0;
}

TEST(DelaunayMesherColmap, MeshesTheFusionOfRealColmap) {
  const std::string colmap = testing::RealColmapBinary();
  if (!std::filesystem::exists(colmap)) GTEST_SKIP() << colmap << " not installed";
  testing::TempDir dir;
  const MeshingScene scene = MakeObjectScene(8, 160, 120);
  WriteFusionWorkspace(dir.path(), scene);
  std::string log;
  ASSERT_EQ(testing::RunShell("QT_QPA_PLATFORM=offscreen " + colmap +
                                  " stereo_fusion --workspace_path " + dir.path() +
                                  " --input_type geometric --output_path " + dir.path() +
                                  "/fused.ply",
                              &log),
            0)
      << log;

  DelaunayMeshingInput input = ReadDenseMeshingInput(dir.path());
  ASSERT_GT(input.points.size(), 1000u) << log;
  // File order: the listed images see the points.
  // (Fused points are averages of a few pixels: near silhouettes a few fall a little
  // outside a listed view's visible surface, hence not 100%.)
  const double file_order = FractionConsistent(scene, input);
  std::printf("images seeing their points: %.3f in file order\n", file_order);
  EXPECT_GT(file_order, 0.9);
  // Sorted by id, the same indices name the wrong images (so the test can tell).
  std::vector<size_t> by_id(std::size(kImageIds));
  for (size_t k = 0; k < by_id.size(); ++k) by_id[k] = k;
  std::sort(by_id.begin(), by_id.end(),
            [](size_t a, size_t b) { return kImageIds[a] < kImageIds[b]; });
  DelaunayMeshingInput sorted = input;
  for (size_t k = 0; k < by_id.size(); ++k) sorted.cameras[k] = scene.cameras[by_id[k]];
  const double sorted_order = FractionConsistent(scene, sorted);
  std::printf("images seeing their points: %.3f when sorted by id\n", sorted_order);
  EXPECT_LT(sorted_order, file_order - 0.2);

  // Mesh it: fused points from exact depth lie on the surface up to the fusion's
  // averaging.
  DelaunayMeshingOptions options;
  options.num_threads = 2;
  const DelaunayMeshingStats stats =
      DenseDelaunayMeshing(dir.path(), dir / "meshed-delaunay.ply", options);
  std::printf("colmap fusion: %s\n", stats.Summary().c_str());
  std::vector<Eigen::Vector3d> true_points;
  for (const auto& p : input.points) true_points.push_back(p);
  const TriangleMesh mesh = ReadPlyMesh(dir / "meshed-delaunay.ply");
  const MeshAccuracy acc = EvaluateMesh(scene, mesh, true_points, 0.05);
  std::printf("colmap fusion: vertex mean %.4f p90 %.4f, face mean %.4f, coverage %.3f\n",
              acc.vertex_mean, acc.vertex_p90, acc.face_mean, acc.coverage);
  // Scene ~4 m across seen at 160 px: a pixel is ~3 cm at the object, fused points are
  // means of exact samples, so they sit within millimetres of the surface; faces cut
  // corners.
  EXPECT_LT(acc.vertex_mean, 0.01);
  EXPECT_LT(acc.face_mean, 0.02);
  EXPECT_GT(acc.coverage, 0.95);
}

}  // namespace
}  // namespace fvs::mvs

#endif  // FVS_HAVE_CGAL
