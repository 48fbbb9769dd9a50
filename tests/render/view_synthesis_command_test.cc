// `colmap view_synthesis` through the front door on a workspace written by the test:
// held-out views from images.txt (PSNR against ground truth), orbit / interpolate /
// camera path, the optional outputs, and bad input (NaN camera, zero-sized image, no
// mesh, fvs without weights): one ERROR line and a non-zero exit.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "scene/scene_fixture.h"
#include "scene/arc_workspace_test.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::ArcViews;
using testing::FrontDoorBinary;
using testing::MakeTestWorldMesh;
using testing::RunShell;
using testing::TempDir;
using testing::WriteTextFile;

namespace fs = std::filesystem;

class ViewSynthesisCommandTest : public testing::ArcWorkspaceTest {
 protected:
  ViewSynthesisCommandTest() : ArcWorkspaceTest(7, 80, 60) {}
  int Run(const std::string& args, std::string* output) {
    return RunShell("FVS_QUIET=1 " + FrontDoorBinary() +
                        " view_synthesis --workspace_path " + ws_ + " " + args,
                    output);
  }
  // images.txt with the poses of the given views (image ids / cameras of the workspace).
  std::string WriteTargets(const std::vector<int>& which, const std::string& name) {
    std::string text;
    for (int i : which) {
      const PinholeCamera& c = views_[i].camera;
      const Eigen::Vector4d q = RotationToQuaternion(c.R);
      char line[512];
      std::snprintf(line, sizeof(line),
                    "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d %s\n\n", i + 1, q(0),
                    q(1), q(2), q(3), c.t(0), c.t(1), c.t(2), i + 1,
                    views_[i].name.c_str());
      text += line;
    }
    fs::create_directories(dir_ / "targets");
    const std::string path = dir_ / ("targets/" + name);
    WriteTextFile(path, text);
    return path;
  }
  static int Lines(const std::string& s) {
    return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
  }
};

TEST_F(ViewSynthesisCommandTest, RendersHeldOutViewsWithExtras) {
  const std::string targets = WriteTargets({2, 4}, "images.txt");
  const std::string out = dir_ / "out";
  std::string output;
  ASSERT_EQ(Run("--target_images " + targets + " --output_path " + out +
                    " --holdout 1 --write_depth 1 --write_confidence 1 --write_sources 1"
                    " --write_infinity 1",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("blend_s"), std::string::npos) << output;
  for (int i : {2, 4}) {
    const std::string stem = out + "/view_00" + std::to_string(i);
    const Image rendered = colmap::ReadImage(stem + ".png");
    const Image truth = colmap::ReadImage(ws_ + "/images/" + views_[i].name);
    const double psnr = testing::Psnr(rendered, truth);
    std::printf("view_synthesis ulr held-out %d: %.2f dB\n", i, psnr);
    EXPECT_GT(psnr, 26.0);
    const Image depth = colmap::ReadColmapArray(stem + ".depth.bin");
    EXPECT_EQ(depth.width, 80);
    EXPECT_TRUE(fs::exists(stem + ".depth.png"));
    EXPECT_TRUE(fs::exists(stem + ".confidence.png"));
    // The closed test room has a surface everywhere: nothing from infinity.
    const Image infinity = colmap::ReadImage(stem + ".infinity.png");
    EXPECT_EQ(infinity.width, 80);
    EXPECT_EQ(*std::max_element(infinity.data.begin(), infinity.data.end()), 0.f);
    const auto json =
        nlohmann::json::parse(testing::ReadTextFile(stem + ".sources.json"));
    // The adaptive K (the default): at least 2, at most --max_num_sources (10).
    ASSERT_GE(json["sources"].size(), 2u);
    ASSERT_LE(json["sources"].size(), 10u);
    for (const auto& s : json["sources"]) {
      EXPECT_NE(s["name"].get<std::string>(), views_[i].name);  // held out
      EXPECT_GT(s["count"].get<int64_t>(), 0);
    }
  }
  // The second run reuses the depth cache and `nearest` works the same way.
  ASSERT_EQ(Run("--target_images " + targets + " --output_path " + out +
                    " --method nearest --holdout 1",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("0 source depths computed"), std::string::npos) << output;
}

TEST_F(ViewSynthesisCommandTest, OrbitInterpolateAndCameraPath) {
  std::string output;
  ASSERT_EQ(Run("--orbit 3 --scale 0.5 --output_path " + dir_ / "orbit", &output), 0)
      << output;
  for (int i = 0; i < 3; ++i) {
    const Image image =
        colmap::ReadImage(dir_ / ("orbit/frame_0000" + std::to_string(i) + ".png"));
    EXPECT_EQ(image.width, 40);
    EXPECT_EQ(image.height, 30);
  }
  ASSERT_EQ(Run("--interpolate 2 --width 64 --output_path " + dir_ / "interp", &output),
            0)
      << output;
  EXPECT_TRUE(fs::exists(dir_ / "interp/frame_00012.png"));  // 6 segments x 2 + last
  EXPECT_FALSE(fs::exists(dir_ / "interp/frame_00013.png"));
  nlohmann::json path;
  path["render_width"] = 48;
  path["render_height"] = 36;
  const PinholeCamera& c = views_[3].camera;
  Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
  c2w.block<3, 3>(0, 0) = c.R.transpose();
  c2w.col(1).head<3>() *= -1;
  c2w.col(2).head<3>() *= -1;
  c2w.block<3, 1>(0, 3) = c.Center();
  std::vector<double> m;
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < 4; ++k) m.push_back(c2w(r, k));
  }
  path["camera_path"] = {{{"camera_to_world", m}, {"fov", 50.0}, {"aspect", 48.0 / 36}}};
  WriteTextFile(dir_ / "path.json", path.dump());
  ASSERT_EQ(Run("--camera_path " + dir_ / "path.json" + " --output_path " + dir_ / "path",
                &output),
            0)
      << output;
  EXPECT_EQ(colmap::ReadImage(dir_ / "path/frame_00000.png").width, 48);
}

// --shard i/n (batch array jobs): each shard renders every n-th frame under the full
// path's names and writes its own report; together they are the unsharded render, pixel
// for pixel.
TEST_F(ViewSynthesisCommandTest, ShardsTogetherAreTheFullRender) {
  std::string output;
  ASSERT_EQ(Run("--orbit 5 --scale 0.5 --output_path " + dir_ / "full", &output), 0)
      << output;
  for (const char* shard : {"0/2", "1/2"}) {
    ASSERT_EQ(Run("--orbit 5 --scale 0.5 --shard " + std::string(shard) +
                      " --output_path " + dir_ / "sharded",
                  &output),
              0)
        << output;
  }
  for (int i = 0; i < 5; ++i) {
    const std::string name = "frame_0000" + std::to_string(i) + ".png";
    ASSERT_TRUE(fs::exists(dir_ / ("sharded/" + name))) << name;
    EXPECT_EQ(colmap::ReadImage(dir_ / ("sharded/" + name)).data,
              colmap::ReadImage(dir_ / ("full/" + name)).data)
        << name;
  }
  EXPECT_FALSE(fs::exists(dir_ / "sharded/frame_00005.png"));
  // One report per shard, with its own frames only.
  const auto first = nlohmann::json::parse(
      testing::ReadTextFile(dir_ / "sharded/frame_report.shard_0_2.json"));
  const auto second = nlohmann::json::parse(
      testing::ReadTextFile(dir_ / "sharded/frame_report.shard_1_2.json"));
  EXPECT_EQ(first["num_frames"].get<int>(), 3);
  EXPECT_EQ(second["num_frames"].get<int>(), 2);
  // A shard past the end renders nothing and says so; a malformed one is an error.
  ASSERT_EQ(Run("--orbit 2 --shard 3/4 --output_path " + dir_ / "empty", &output), 0)
      << output;
  EXPECT_NE(output.find("no targets"), std::string::npos) << output;
  EXPECT_NE(Run("--orbit 2 --shard 2/2 --output_path " + dir_ / "bad", &output), 0);
}

TEST_F(ViewSynthesisCommandTest, BadInputIsOneLineAndNonZeroExit) {
  std::string output;
  auto expect_failure = [&](const std::string& args, const std::string& fragment) {
    EXPECT_NE(Run(args, &output), 0) << args;
    EXPECT_EQ(Lines(output), 1) << output;
    EXPECT_NE(output.find("ERROR"), std::string::npos) << output;
    EXPECT_NE(output.find(fragment), std::string::npos) << output;
  };
  const std::string out = " --output_path " + dir_ / "bad";
  WriteTextFile(dir_ / "nan.txt", "1 nan 0 0 0 0 0 0 1 x.png\n\n");
  expect_failure("--target_images " + dir_ / "nan.txt" + out, "non-finite pose");
  fs::create_directories(dir_ / "zero");
  WriteTextFile(dir_ / "zero/cameras.txt", "1 PINHOLE 0 0 32 32 20 15\n");
  WriteTextFile(dir_ / "zero/images.txt", "1 1 0 0 0 0 0 0 1 x.png\n\n");
  expect_failure("--target_images " + dir_ / "zero/images.txt" + out, "image size");
  expect_failure("--orbit 2 --method fvs" + out, "method fvs needs model weights");
  expect_failure("--orbit 2 --camera_path x.json" + out, "exactly one of");
  expect_failure("--orbit 2 --num_sources -1" + out, "num_sources");
  fs::remove(ws_ + "/meshed-delaunay.ply");
  expect_failure("--orbit 2" + out, "no proxy mesh");
}

// The generated demo scene (view_synthesis_synthetic, exact mesh as the proxy): two views
// held out and rendered from the others with ulr and nearest, against their photos.
TEST(ViewSynthesisSyntheticTest, HeldOutViewsOfTheGeneratedScene) {
  TempDir dir;
  const std::string ws = dir / "ws";
  std::string output;
  ASSERT_EQ(RunShell("FVS_QUIET=1 " + FrontDoorBinary() + " view_synthesis_synthetic " +
                         "--output_path " + ws + " --SyntheticScene.num_views 8 " +
                         "--SyntheticScene.width 96 --SyntheticScene.height 72 " +
                         "--SyntheticScene.write_proxy_mesh 1",
                     &output),
            0)
      << output;
  const colmap::Reconstruction rec = colmap::ReadSparseModel(ws + "/sparse");
  std::string text;
  std::vector<std::string> names;
  for (const auto& [id, image] : rec.images) {
    if (id != 3 && id != 6) continue;
    char line[512];
    std::snprintf(
        line, sizeof(line), "%u %.17g %.17g %.17g %.17g %.17g %.17g %.17g %u %s\n\n", id,
        image.qvec(0), image.qvec(1), image.qvec(2), image.qvec(3), image.tvec(0),
        image.tvec(1), image.tvec(2), image.camera_id, image.name.c_str());
    text += line;
    names.push_back(image.name);
  }
  ASSERT_EQ(names.size(), 2u);
  WriteTextFile(dir / "images.txt", text);
  double psnr[2] = {0, 0};
  const char* methods[2] = {"ulr", "nearest"};
  for (int m = 0; m < 2; ++m) {
    ASSERT_EQ(RunShell("FVS_QUIET=1 " + FrontDoorBinary() +
                           " view_synthesis --workspace_path " + ws + " --output_path " +
                           dir / methods[m] + " --target_images " + dir / "images.txt" +
                           " --holdout 1 --method " + methods[m],
                       &output),
              0)
        << output;
    for (const std::string& name : names) {
      const std::string stem = fs::path(name).replace_extension().string();
      const Image rendered =
          colmap::ReadImage(dir / (std::string(methods[m]) + "/" + stem + ".png"));
      const Image truth = colmap::ReadImage(ws + "/images/" + name);
      psnr[m] += testing::Psnr(rendered, truth) / names.size();
    }
    std::printf("generated scene, held out: %s %.2f dB\n", methods[m], psnr[m]);
  }
  // Measured 21.5 dB (ulr) and 14.6 dB (nearest) at this tiny size: the procedural
  // textures alias at 96x72, so resampling costs more than on the fixture world; the
  // benchmark gives ~31 dB at 480x270. The bound leaves 2.5 dB of slack.
  EXPECT_GT(psnr[0], 19.0);
  EXPECT_GE(psnr[0], psnr[1] - 0.5);
}

}  // namespace
}  // namespace fvs
