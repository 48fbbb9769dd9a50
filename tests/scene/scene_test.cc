// Scene loading from a COLMAP dense workspace: centring, the source depth cache (written,
// reused, invalidated by a new mesh), errors for missing parts, far-from-origin
// invariance.
#include "fvs/scene/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <thread>

#include "colmap_ext/dense_io.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::ArcViews;
using testing::MakeTestWorldMesh;
using testing::TempDir;
using testing::WriteTestWorkspace;

TEST(SceneTest, LoadsCentresAndCachesSourceDepths) {
  TempDir dir;
  const std::string ws = dir / "ws";
  const Eigen::Vector3d offset(600, -800, 0);
  const auto views = ArcViews(4, 40, 30, offset);
  const TriangleMesh mesh = MakeTestWorldMesh(offset);
  WriteTestWorkspace(ws, views, mesh);

  const Scene scene = Scene::Load(ws);
  ASSERT_EQ(scene.num_views(), 4);
  EXPECT_EQ(scene.num_depths_computed(), 4);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const SceneView& v : scene.views()) mean += v.camera.Center() / 4;
  EXPECT_LT(mean.norm(), 1e-9);
  EXPECT_LT((scene.origin() - offset).norm(), 4.0);  // mean camera centre
  for (int i = 0; i < 4; ++i) {
    const int j = scene.FindView(views[i].name);
    ASSERT_GE(j, 0);
    // The world camera comes back through the origin.
    const PinholeCamera world = scene.ToWorldCamera(scene.view(j).camera);
    EXPECT_LT((world.t - views[i].camera.t).norm(), 1e-6);
    const std::string cached = ws + "/fvs/depth/" + views[i].name + ".bin";
    ASSERT_TRUE(std::filesystem::exists(cached));
    const Image depth = colmap::ReadColmapArray(cached);
    EXPECT_EQ(depth.data, scene.SourceDepth(j).data);
    // Depth of the closed room: every pixel has a surface.
    for (float d : depth.data) EXPECT_GT(d, 0.f);
    const Image& photo = scene.SourceImage(j);
    EXPECT_EQ(photo.width, 40);
    EXPECT_EQ(photo.channels, 3);
  }
  EXPECT_EQ(scene.FindView("nope.png"), -1);

  const Scene again = Scene::Load(ws);
  EXPECT_EQ(again.num_depths_computed(), 0);
  // A new mesh (different size) invalidates every cached depth.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  WritePlyMesh(ws + "/meshed-delaunay.ply", MakeTestWorldMesh(offset, 0.5),
               PlyWriteOptions{PlyFormat::kBinaryLittleEndian, true});
  const Scene third = Scene::Load(ws);
  EXPECT_EQ(third.num_depths_computed(), 4);
  // Without the cache nothing is read or written.
  SceneLoadOptions no_cache;
  no_cache.use_depth_cache = false;
  EXPECT_EQ(Scene::Load(ws, no_cache).num_depths_computed(), 4);
}

TEST(SceneTest, FarFromOriginGivesTheSameDepths) {
  const auto near_views = ArcViews(3, 40, 30);
  const auto far_views = ArcViews(3, 40, 30, Eigen::Vector3d(1e4, 0, 0));
  const Scene near_scene = Scene::FromWorld(near_views, MakeTestWorldMesh());
  const Scene far_scene =
      Scene::FromWorld(far_views, MakeTestWorldMesh(Eigen::Vector3d(1e4, 0, 0)));
  for (int i = 0; i < 3; ++i) {
    const Image& a = near_scene.SourceDepth(i);
    const Image& b = far_scene.SourceDepth(i);
    double max_diff = 0;
    for (size_t k = 0; k < a.data.size(); ++k) {
      max_diff = std::max(max_diff, std::abs(double(a.data[k]) - b.data[k]) / a.data[k]);
    }
    EXPECT_LT(max_diff, 1e-5);
  }
}

TEST(SceneTest, MissingPartsAreClearErrors) {
  TempDir dir;
  const std::string ws = dir / "ws";
  WriteTestWorkspace(ws, ArcViews(2, 20, 15), MakeTestWorldMesh(), /*write_mesh=*/false);
  try {
    Scene::Load(ws);
    FAIL() << "no error for a workspace without a mesh";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("meshed-delaunay.ply"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("no proxy mesh"), std::string::npos);
  }
  EXPECT_THROW(Scene::Load(dir / "missing"), Error);
  // A photo missing from images/ fails when it is needed, naming the file.
  WritePlyMesh(ws + "/meshed-delaunay.ply", MakeTestWorldMesh());
  std::filesystem::remove(ws + "/images/view_001.png");
  const Scene scene = Scene::Load(ws);
  EXPECT_THROW(scene.SourceImage(scene.FindView("view_001.png")), Error);
  // In-memory photos must match the camera.
  Scene memory = Scene::FromWorld(ArcViews(1, 20, 15), MakeTestWorldMesh());
  EXPECT_THROW(memory.SetSourceImage(0, Image(10, 10, 3)), Error);
  EXPECT_THROW(memory.SourceImage(0), Error);
}

}  // namespace
}  // namespace fvs
