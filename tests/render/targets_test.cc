// Target cameras: COLMAP images.txt (+ cameras.txt), nerfstudio camera paths, orbit and
// interpolation, output sizes, and the bad inputs (NaN pose, zero size, unknown camera).
#include "fvs/render/targets.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::ArcCamera;
using testing::TempDir;
using testing::WriteTextFile;

Scene SmallScene() {
  return Scene::FromWorld(testing::ArcViews(4, 40, 30), testing::MakeTestWorldMesh());
}

TEST(TargetsTest, ReadsImagesTxtWithCamerasBesideOrFromTheScene) {
  TempDir dir;
  const Scene scene = SmallScene();
  const PinholeCamera cam = ArcCamera(0.3, 40, 30);
  const Eigen::Vector4d q = RotationToQuaternion(cam.R);
  char line[512];
  std::snprintf(line, sizeof(line),
                "7 %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d a/b.jpg\n", q(0), q(1),
                q(2), q(3), cam.t(0), cam.t(1), cam.t(2), 3);
  // With a POINTS2D line (empty) and without: both are accepted.
  WriteTextFile(dir / "images.txt", std::string("# comment\n") + line + "\n" + line +
                                        std::string(line).replace(0, 1, "8"));
  WriteTextFile(dir / "cameras.txt", "# c\n3 SIMPLE_PINHOLE 80 60 64 40 30\n");
  auto targets = ReadTargetImagesTxt(dir / "images.txt", scene);
  ASSERT_EQ(targets.size(), 3u);
  EXPECT_EQ(targets[0].name, "a/b");
  EXPECT_EQ(targets[0].image_name, "a/b.jpg");
  EXPECT_EQ(targets[0].camera.width, 80);
  EXPECT_DOUBLE_EQ(targets[0].camera.fx, 64);
  EXPECT_LT((targets[0].camera.R - cam.R).norm(), 1e-12);
  EXPECT_LT((targets[0].camera.t - cam.t).norm(), 1e-12);

  // No cameras.txt: the workspace camera with that id (the in-memory views use id 1).
  TempDir other;
  std::string text = line;
  text.replace(text.find(" 3 a/b"), 6, " 1 a/b");
  WriteTextFile(other / "images.txt", text);
  targets = ReadTargetImagesTxt(other / "images.txt", scene);
  ASSERT_EQ(targets.size(), 1u);
  EXPECT_EQ(targets[0].camera.width, 40);
}

TEST(TargetsTest, BadImagesTxtAreErrors) {
  TempDir dir;
  const Scene scene = SmallScene();
  WriteTextFile(dir / "cameras.txt", "1 PINHOLE 40 30 32 32 20 15\n");
  auto expect_error = [&](const std::string& images, const std::string& fragment) {
    WriteTextFile(dir / "images.txt", images);
    try {
      ReadTargetImagesTxt(dir / "images.txt", scene);
      FAIL() << "no error for: " << images;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error("1 nan 0 0 0 0 0 0 1 x.png\n\n", "non-finite pose");
  expect_error("1 1 0 0 0 0 inf 0 1 x.png\n\n", "non-finite pose");
  expect_error("1 0 0 0 0 0 0 0 1 x.png\n\n", "zero quaternion");
  expect_error("1 1 0 0 0 0 0 0 9 x.png\n\n", "camera 9");
  expect_error("1 1 0 0\n", "expected IMAGE_ID");
  expect_error("", "no target images");
  WriteTextFile(dir / "cameras.txt", "2 PINHOLE 0 30 32 32 20 15\n");
  expect_error("1 1 0 0 0 0 0 0 2 x.png\n\n", "image size must be positive");
  WriteTextFile(dir / "cameras.txt", "2 OPENCV 40 30 32 32 20 15 0 0 0 0\n");
  expect_error("1 1 0 0 0 0 0 0 2 x.png\n\n", "has distortion");
  // Camera ids are whole numbers that fit uint32 (1e20 was cast to uint32_t: undefined
  // behaviour, reproduced by tests/fuzz/target_images_fuzzer).
  for (const char* id : {"1e20", "-1", "2.5", "4294967296"}) {
    std::filesystem::remove(dir / "cameras.txt");  // read first, when there
    expect_error(std::string("1 1 0 0 0 0 0 0 ") + id + " x.png\n\n",
                 "expected IMAGE_ID");
    WriteTextFile(dir / "cameras.txt", std::string(id) + " PINHOLE 40 30 32 32 20 15\n");
    expect_error("1 1 0 0 0 0 0 0 2 x.png\n\n", "malformed camera line");
  }
}

TEST(TargetsTest, NerfstudioCameraPathRoundTrip) {
  TempDir dir;
  const PinholeCamera cam = ArcCamera(0.2, 64, 48);
  // Our camera -> OpenGL camera-to-world: columns x, -y, -z of R^T, centre.
  Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
  c2w.block<3, 3>(0, 0) = cam.R.transpose();
  c2w.col(1).head<3>() *= -1;
  c2w.col(2).head<3>() *= -1;
  c2w.block<3, 1>(0, 3) = cam.Center();
  nlohmann::json json;
  json["render_width"] = 64;
  json["render_height"] = 48;
  std::vector<double> m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m.push_back(c2w(r, c));
  }
  const double fov = 2 * std::atan(0.5 * 48 / cam.fy) * 180 / M_PI;
  json["camera_path"] = {{{"camera_to_world", m}, {"fov", fov}, {"aspect", 64.0 / 48}}};
  WriteTextFile(dir / "path.json", json.dump());
  const auto targets = ReadNerfstudioCameraPath(dir / "path.json");
  ASSERT_EQ(targets.size(), 1u);
  EXPECT_EQ(targets[0].name, "frame_00000");
  EXPECT_LT((targets[0].camera.R - cam.R).norm(), 1e-9);
  EXPECT_LT((targets[0].camera.t - cam.t).norm(), 1e-9);
  EXPECT_NEAR(targets[0].camera.fy, cam.fy, 1e-9);

  json["camera_path"][0]["fov"] = 0;
  WriteTextFile(dir / "bad.json", json.dump());
  EXPECT_THROW(ReadNerfstudioCameraPath(dir / "bad.json"), Error);
  WriteTextFile(dir / "bad.json", "{\"camera_path\": [");
  EXPECT_THROW(ReadNerfstudioCameraPath(dir / "bad.json"), Error);
  WriteTextFile(dir / "bad.json",
                "{\"render_width\": 0, \"render_height\": 4, \"camera_path\": []}");
  EXPECT_THROW(ReadNerfstudioCameraPath(dir / "bad.json"), Error);
  // Sizes that do not fit an int: 1e30 was cast to int (undefined behaviour) and
  // 4294967360 wrapped to 64 (reproduced by tests/fuzz/camera_path_fuzzer).
  for (const char* size : {"1e30", "4294967360", "64.5", "\"64\""}) {
    json["render_width"] = nlohmann::json::parse(size);
    WriteTextFile(dir / "bad.json", json.dump());
    try {
      ReadNerfstudioCameraPath(dir / "bad.json");
      FAIL() << "no error for render_width " << size;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("render_width"), std::string::npos)
          << e.what();
    }
  }
}

TEST(TargetsTest, OrbitLooksAtTheCentreAndInterpolationHitsTheViews) {
  const Scene scene = SmallScene();
  const auto orbit = OrbitTargets(scene, 8);
  ASSERT_EQ(orbit.size(), 8u);
  for (const auto& t : orbit) {
    const PinholeCamera c = scene.ToSceneCamera(t.camera);
    EXPECT_TRUE(c.IsValid());
    // The mesh is visible: the centre of the image sees a surface.
    const Image depth = scene.RenderDepth(c);
    EXPECT_GT(depth.at(20, 15), 0.f);
  }
  EXPECT_EQ(orbit[3].name, "frame_00003");
  const auto path = InterpolateTargets(scene, 3);
  ASSERT_EQ(path.size(), 3u * 3 + 1);
  EXPECT_LT((path[0].camera.t - scene.ToWorldCamera(scene.view(0).camera).t).norm(),
            1e-9);
  EXPECT_LT((path[3].camera.R - scene.view(1).camera.R).norm(), 1e-9);
  EXPECT_LT(
      (path.back().camera.Center() - scene.ToWorldCamera(scene.view(3).camera).Center())
          .norm(),
      1e-9);
  EXPECT_THROW(OrbitTargets(scene, 0), Error);
  EXPECT_THROW(InterpolateTargets(scene, 0), Error);
}

TEST(TargetsTest, ResizeTarget) {
  const PinholeCamera cam = ArcCamera(0, 40, 30);
  EXPECT_EQ(ResizeTarget(cam, 80, 0, 1.0).height, 60);
  EXPECT_EQ(ResizeTarget(cam, 0, 15, 1.0).width, 20);
  const PinholeCamera half = ResizeTarget(cam, 0, 0, 0.5);
  EXPECT_EQ(half.width, 20);
  EXPECT_DOUBLE_EQ(half.fx, cam.fx / 2);
  EXPECT_THROW(ResizeTarget(cam, 0, 0, 0.0), Error);
  EXPECT_THROW(ResizeTarget(cam, 0, 0, 1e-4), Error);
}

}  // namespace
}  // namespace fvs
