// The written synthetic workspace: every file read back by our COLMAP readers and matched
// against the in-memory scene, byte-identical output for a seed, the ground-truth model
// accepted by the real `colmap model_analyzer`, and the command through the front door.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/ply.h"
#include "fvs/synthetic/generate.h"
#include "fvs/synthetic/render.h"
#include "support/test_support.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;
using testing::ReadTextFile;
using testing::RunShell;
using testing::TempDir;

SyntheticSceneOptions SmallOptions(uint64_t seed) {
  SyntheticSceneOptions options;
  options.seed = seed;
  options.num_views = 6;
  options.width = 160;
  options.height = 120;
  options.num_sparse_points = 400;
  return options;
}

TEST(SyntheticOutput, FilesReadBackAndMatchTheScene) {
  TempDir dir;
  SyntheticSceneOptions options = SmallOptions(4);
  options.write_proxy_mesh = true;
  GenerateSyntheticScene(options, dir.path());
  const SyntheticScene scene = BuildSyntheticScene(options);

  EXPECT_FALSE(fs::exists(dir / "stereo"));
  EXPECT_TRUE(fs::exists(dir / "meshed-delaunay.ply"));

  // Sparse model: one PINHOLE camera, exact poses, tracks that project exactly.
  const colmap::Reconstruction model = colmap::ReadSparseModel(dir / "sparse");
  EXPECT_NO_THROW(model.Check("ground truth"));
  ASSERT_EQ(model.cameras.size(), 1u);
  const colmap::Camera& camera = model.cameras.begin()->second;
  EXPECT_EQ(camera.model_id, colmap::kPinhole);
  EXPECT_EQ(camera.width, 160u);
  EXPECT_EQ(camera.params[0], scene.cameras[0].fx);
  ASSERT_EQ(model.images.size(), 6u);
  EXPECT_GT(model.points3D.size(), 200u);
  for (int i = 0; i < 6; ++i) {
    const colmap::Image* image = model.FindImageByName(scene.image_names[i]);
    ASSERT_NE(image, nullptr);
    EXPECT_LT((image->Rotation() - scene.cameras[i].R).norm(), 1e-9);
    EXPECT_LT((image->tvec - scene.cameras[i].t).norm(), 1e-9);
    for (const colmap::Point2D& p : image->points2D) {
      ASSERT_NE(p.point3D_id, colmap::kInvalidPoint3DId);
      const Eigen::Vector3d xc =
          scene.cameras[i].WorldToCamera(model.points3D.at(p.point3D_id).xyz);
      EXPECT_GT(xc.z(), 0);
      EXPECT_LT((scene.cameras[i].CameraToPixel(xc) - p.xy).norm(), 1e-6);
    }
  }
  for (const auto& [id, point] : model.points3D) EXPECT_GE(point.track.size(), 2u);

  // Images, depth and normal maps equal the in-memory rendering.
  for (int i : {0, 5}) {
    const std::string& name = scene.image_names[i];
    Image color, depth, normals;
    RenderSyntheticView(scene, scene.cameras[i], &color, &depth, &normals);
    const Image png = colmap::ReadImage(dir / ("images/" + name));
    ASSERT_EQ(png.width, 160);
    ASSERT_EQ(png.height, 120);
    for (size_t k = 0; k < png.data.size(); ++k) {
      ASSERT_NEAR(png.data[k], color.data[k], 0.5 / 255 + 1e-6);
    }
    const Image depth_read =
        colmap::ReadColmapArray(SyntheticDepthMapPath(dir.path(), name));
    const Image normals_read =
        colmap::ReadColmapArray(SyntheticNormalMapPath(dir.path(), name));
    ASSERT_EQ(depth_read.channels, 1);
    ASSERT_EQ(normals_read.channels, 3);
    EXPECT_TRUE(depth_read.data == depth.data);
    EXPECT_TRUE(normals_read.data == normals.data);
  }

  const TriangleMesh mesh = ReadPlyMesh(SyntheticMeshPath(dir.path()));
  EXPECT_EQ(mesh.vertices.size(), scene.mesh.vertices.size());
  EXPECT_EQ(mesh.faces.size(), scene.mesh.faces.size());
  EXPECT_EQ(mesh.colors.size(), scene.mesh.colors.size());

  const nlohmann::json info =
      nlohmann::json::parse(ReadTextFile(SyntheticSceneJsonPath(dir.path())));
  EXPECT_EQ(info.at("seed").get<uint64_t>(), 4u);
  EXPECT_NEAR(info.at("scene_size").get<double>(), scene.scene_size, 1e-9);
  EXPECT_EQ(info.at("image_names").size(), 6u);
}

TEST(SyntheticOutput, SameSeedSameBytesOtherSeedOtherImages) {
  TempDir a, b, c;
  GenerateSyntheticScene(SmallOptions(11), a.path());
  GenerateSyntheticScene(SmallOptions(11), b.path());
  GenerateSyntheticScene(SmallOptions(12), c.path());
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a.path())) {
    if (!entry.is_regular_file()) continue;
    const std::string relative = fs::relative(entry.path(), a.path()).string();
    EXPECT_EQ(ReadTextFile(entry.path().string()), ReadTextFile(b / relative))
        << relative;
    ++compared;
  }
  EXPECT_EQ(compared, 6 * 3 + 3 + 2);  // images/depth/normals, sparse, mesh + json
  EXPECT_NE(ReadTextFile(a / "images/frame_0002.png"),
            ReadTextFile(c / "images/frame_0002.png"));
}

TEST(SyntheticOutput, RealColmapAcceptsTheGroundTruthModel) {
  TempDir dir;
  GenerateSyntheticScene(SmallOptions(5), dir.path());
  const colmap::Reconstruction model = colmap::ReadSparseModel(dir / "sparse");
  std::string output;
  ASSERT_EQ(RunShell("QT_QPA_PLATFORM=offscreen " + testing::RealColmapBinary() +
                         " model_analyzer --path " + (dir / "sparse"),
                     &output),
            0)
      << output;
  EXPECT_NE(output.find("Cameras: 1"), std::string::npos) << output;
  EXPECT_NE(output.find("Registered images: 6"), std::string::npos) << output;
  EXPECT_NE(output.find("Points: " + std::to_string(model.points3D.size())),
            std::string::npos)
      << output;
  // COLMAP's own text export of our binary model must read back the same poses.
  fs::create_directories(dir / "txt");
  ASSERT_EQ(RunShell(testing::RealColmapBinary() + " model_converter --input_path " +
                         (dir / "sparse") + " --output_path " + (dir / "txt") +
                         " --output_type TXT",
                     &output),
            0)
      << output;
  const colmap::Reconstruction text = colmap::ReadSparseModelText(dir / "txt");
  ASSERT_EQ(text.images.size(), 6u);
  for (const auto& [id, image] : model.images) {
    EXPECT_LT((text.images.at(id).tvec - image.tvec).norm(), 1e-9);
  }
}

TEST(SyntheticOutput, CommandThroughTheFrontDoor) {
  const std::string front_door = testing::FrontDoorBinary();
  if (!fs::exists(front_door)) GTEST_SKIP() << "front door not built: " << front_door;
  TempDir dir;
  std::string output;
  const std::string base =
      front_door + " view_synthesis_synthetic --output_path " + dir.path();
  EXPECT_EQ(RunShell("FVS_QUIET=1 " + base +
                         " --SyntheticScene.num_views 3 --SyntheticScene.width 64"
                         " --SyntheticScene.height 48 --SyntheticScene.seed 9",
                     &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(dir / "images/frame_0002.png"));
  EXPECT_TRUE(fs::exists(dir / "ground_truth/scene.json"));
  EXPECT_EQ(RunShell(base + " --SyntheticScene.num_views 0", &output), 1);
  EXPECT_NE(output.find("ERROR: SyntheticScene: num_views"), std::string::npos) << output;
  EXPECT_EQ(RunShell(front_door + " view_synthesis_synthetic", &output), 1);
  EXPECT_NE(output.find("output_path"), std::string::npos) << output;
}

}  // namespace
}  // namespace fvs
