// Camera paths: interpolation through keyframes, smoothness, Ceres smoothing (less jerk,
// near the keyframes), constant speed, single / repeated keyframes, coverage flags, and
// the camera_path.json / images.txt round trips (also through the real COLMAP).
#include "fvs/path/camera_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "fvs/path/path_spline.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::ArcCamera;
using testing::LookAtCamera;
using testing::TempDir;

// Keyframes on the fixture's arc plus one off it, far from the origin to exercise the
// centring.
std::vector<CameraPathKeyframe> Keys(
    const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  std::vector<CameraPathKeyframe> keys;
  const double angles[] = {-0.6, -0.1, 0.3, 0.6};
  for (int i = 0; i < 4; ++i) {
    PinholeCamera c = ArcCamera(angles[i], 80, 60, offset);
    c.fx = c.fy;  // square pixels, centred
    keys.push_back({"key" + std::to_string(i), c});
  }
  // A wiggle in height and rotation to give the path some jerk.
  keys[1].camera = LookAtCamera(keys[1].camera.Center() + Eigen::Vector3d(0, 0, 0.4),
                                Eigen::Vector3d(0.3, 0, 0.9) + offset, 80, 60);
  return keys;
}

double MaxCentreStep(const std::vector<TargetCamera>& f, int j) {
  return (f[j + 1].camera.Center() - f[j].camera.Center()).norm();
}

TEST(CameraPathTest, InterpolationPassesThroughKeyframes) {
  const auto keys = Keys(Eigen::Vector3d(1e4, -2e4, 5e3));
  CameraPathOptions o;
  o.smooth = false;
  o.constant_speed = false;
  o.fps = 10;
  o.seconds_per_keyframe = 1.5;  // 15 frames per segment, keys at frames 0, 15, 30, 45
  const auto frames = InterpolateCameraPath(keys, o);
  ASSERT_EQ(frames.size(), 46u);
  EXPECT_EQ(frames[0].name, "frame_00000");
  for (int k = 0; k < 4; ++k) {
    const PinholeCamera& f = frames[15 * k].camera;
    EXPECT_LT((f.Center() - keys[k].camera.Center()).norm(), 1e-8) << k;
    EXPECT_LT((f.R - keys[k].camera.R).cwiseAbs().maxCoeff(), 1e-9) << k;
    EXPECT_NEAR(f.fy, keys[k].camera.fy, 1e-9);
  }
  // Continuity: no jump (the speed may change at a key, the position may not).
  double mean_step = 0;
  for (size_t j = 0; j + 1 < frames.size(); ++j) mean_step += MaxCentreStep(frames, j);
  mean_step /= frames.size() - 1;
  for (size_t j = 0; j + 1 < frames.size(); ++j) {
    EXPECT_LT(MaxCentreStep(frames, j), 2.5 * mean_step) << j;
    const double angle = Eigen::Quaterniond(frames[j].camera.R)
                             .angularDistance(Eigen::Quaterniond(frames[j + 1].camera.R));
    EXPECT_LT(angle, 0.1) << j;
  }
}

TEST(CameraPathTest, SmoothingReducesJerkAndStaysNearKeyframes) {
  const auto keys = Keys();
  CameraPathOptions o;
  o.fps = 15;
  o.smooth = true;
  const CameraPathResult r = ComputeCameraPath(keys, o);
  ASSERT_EQ(r.frames.size(), 91u);
  EXPECT_GT(r.before.jerk, 0);
  EXPECT_LT(r.after.jerk, 0.7 * r.before.jerk)
      << "before " << r.before.jerk << " after " << r.after.jerk;
  EXPECT_LT(r.after.rotation_jerk, r.before.rotation_jerk);
  // Near the keyframes: a small share of the path's extent (about 3.5 units).
  EXPECT_LT(r.after.keyframe_error, 0.1) << r.after.keyframe_error;
  EXPECT_LT(r.after.keyframe_angle_deg, 3.0);
  for (const TargetCamera& f : r.frames) EXPECT_TRUE(f.camera.IsValid()) << f.name;
}

TEST(CameraPathTest, ConstantSpeed) {
  // Uneven keyframe spacing: 0.1 then 2.0 apart.
  std::vector<CameraPathKeyframe> keys;
  for (double x : {0.0, 0.1, 2.1}) {
    keys.push_back(
        {"k", LookAtCamera(Eigen::Vector3d(x, 0, 1), Eigen::Vector3d(x, 5, 1), 64, 48)});
  }
  CameraPathOptions o;
  o.smooth = false;
  o.fps = 20;
  o.constant_speed = true;
  const auto frames = InterpolateCameraPath(keys, o);
  ASSERT_EQ(frames.size(), 81u);
  double lo = 1e9, hi = 0;
  for (size_t j = 0; j + 1 < frames.size(); ++j) {
    lo = std::min(lo, MaxCentreStep(frames, j));
    hi = std::max(hi, MaxCentreStep(frames, j));
  }
  EXPECT_LT(hi - lo, 0.02 * hi) << lo << " " << hi;
  // Smooth: consecutive steps keep their direction (no loop or overshoot).
  for (size_t j = 1; j + 1 < frames.size(); ++j) {
    const Eigen::Vector3d a = frames[j].camera.Center() - frames[j - 1].camera.Center();
    const Eigen::Vector3d b = frames[j + 1].camera.Center() - frames[j].camera.Center();
    EXPECT_GT(a.normalized().dot(b.normalized()), 0.99) << j;
  }
  o.constant_speed = false;
  const auto uneven = InterpolateCameraPath(keys, o);
  EXPECT_GT(MaxCentreStep(uneven, 60), 5 * MaxCentreStep(uneven, 10));
}

TEST(CameraPathTest, SingleAndRepeatedKeyframesStayFinite) {
  auto keys = Keys();
  CameraPathOptions o;
  o.fps = 10;
  // One keyframe: one frame, or a still shot for a given duration.
  auto one = InterpolateCameraPath({keys[0]}, o);
  ASSERT_EQ(one.size(), 1u);
  o.duration_s = 1;
  one = InterpolateCameraPath({keys[0]}, o);
  ASSERT_EQ(one.size(), 11u);
  for (const auto& f : one) {
    EXPECT_LT((f.camera.Center() - keys[0].camera.Center()).norm(), 1e-9);
  }
  // The same pose repeated, and a pure rotation about one centre.
  o.duration_s = 0;
  const auto same = InterpolateCameraPath({keys[1], keys[1], keys[1]}, o);
  for (const auto& f : same) {
    ASSERT_TRUE(f.camera.IsValid());
    EXPECT_LT((f.camera.Center() - keys[1].camera.Center()).norm(), 1e-6);
  }
  const Eigen::Vector3d eye(0, 0, 1);
  std::vector<CameraPathKeyframe> turn = {
      {"a", LookAtCamera(eye, Eigen::Vector3d(1, 0, 1), 64, 48)},
      {"b", LookAtCamera(eye, Eigen::Vector3d(-1, 0.01, 1), 64, 48)}};  // 180 degrees
  for (const auto& f : InterpolateCameraPath(turn, o)) {
    ASSERT_TRUE(f.camera.IsValid());
    EXPECT_TRUE(f.camera.R.allFinite());
    EXPECT_LT((f.camera.Center() - eye).norm(), 1e-6);
  }
}

TEST(CameraPathTest, LowCoverageFramesArePulledBackAndFlagged) {
  const Scene scene = testing::MakeTestScene(6, 80, 60);
  // From a registered view out through the wall of the room and back: the middle of the
  // path sees nothing the sources see.
  const PinholeCamera inside = ArcCamera(0.0, 80, 60);
  std::vector<CameraPathKeyframe> keys = {
      {"in", inside},
      {"out",
       LookAtCamera(Eigen::Vector3d(9, 0, 1.6), Eigen::Vector3d(20, 0, 1.6), 80, 60)},
      {"back", ArcCamera(0.3, 80, 60)}};
  for (auto& k : keys) k.camera.fx = k.camera.fy;
  CameraPathOptions o;
  o.fps = 5;
  o.coverage_width = 40;
  const CameraPathResult r = ComputeCameraPath(keys, o, &scene);
  ASSERT_EQ(r.coverage.size(), r.frames.size());
  EXPECT_GT(r.before.num_low_coverage, 0);
  EXPECT_LT(r.before.min_coverage, 0.1);
  EXPECT_GE(r.coverage.front(), 0.5);
  for (double c : r.coverage) EXPECT_TRUE(std::isfinite(c) && c >= 0 && c <= 1);
  // The path is pulled in where it can be; the keyframe outside stays flagged.
  EXPECT_GE(r.after.mean_coverage, r.before.mean_coverage);
  EXPECT_GT(r.after.num_low_coverage, 0);
  for (const auto& f : r.frames) EXPECT_TRUE(f.camera.IsValid());
}

TEST(CameraPathTest, CameraPathJsonRoundTrip) {
  TempDir dir;
  const auto keys = Keys(Eigen::Vector3d(300, 20, -7));
  CameraPathOptions o;
  o.fps = 8;
  const auto frames = InterpolateCameraPath(keys, o);
  const std::string path = dir / "camera_path.json";
  WriteNerfstudioCameraPath(path, keys, frames, o);
  const auto back = ReadNerfstudioCameraPath(path);
  ASSERT_EQ(back.size(), frames.size());
  for (size_t j = 0; j < frames.size(); ++j) {
    const PinholeCamera &a = frames[j].camera, &b = back[j].camera;
    EXPECT_EQ(back[j].name, frames[j].name);
    EXPECT_EQ(a.width, b.width);
    EXPECT_NEAR(a.fy, b.fy, 1e-9 * a.fy);
    EXPECT_NEAR(a.cx, b.cx, 1e-12);
    EXPECT_LT((a.Center() - b.Center()).norm(), 1e-9);
    EXPECT_LT((a.R - b.R).cwiseAbs().maxCoeff(), 1e-12);
  }
  const auto keys_back = ReadNerfstudioKeyframes(path);
  ASSERT_EQ(keys_back.size(), keys.size());
  for (size_t k = 0; k < keys.size(); ++k) {
    EXPECT_EQ(keys_back[k].name, keys[k].name);
    EXPECT_LT((keys_back[k].camera.Center() - keys[k].camera.Center()).norm(), 1e-9);
    EXPECT_LT((keys_back[k].camera.R - keys[k].camera.R).cwiseAbs().maxCoeff(), 1e-12);
  }
  // A legacy nerfstudio keyframe: column-major three.js matrix as a string.
  nlohmann::json legacy;
  legacy["render_width"] = 80;
  legacy["render_height"] = 60;
  std::vector<double> col(16);
  Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
  c2w.block<3, 1>(0, 3) = Eigen::Vector3d(1, 2, 3);
  for (int e = 0; e < 16; ++e) col[e] = c2w(e % 4, e / 4);
  legacy["keyframes"] = {
      {{"matrix", nlohmann::json(col).dump()}, {"fov", 50}, {"aspect", 4.0 / 3}}};
  legacy["camera_path"] = nlohmann::json::array();
  testing::WriteTextFile(dir / "legacy.json", legacy.dump());
  const auto lk = ReadNerfstudioKeyframes(dir / "legacy.json");
  ASSERT_EQ(lk.size(), 1u);
  EXPECT_LT((lk[0].camera.Center() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_EQ(lk[0].camera.width, 80);
  // Bad files: one clear error naming the file.
  testing::WriteTextFile(dir / "bad.json", "{\"keyframes\": [{\"fov\": 50}]}");
  try {
    ReadNerfstudioKeyframes(dir / "bad.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
  }
  // Sizes that do not fit an int, and an aspect with no int width: each was cast to int
  // (undefined behaviour, reproduced by tests/fuzz/camera_path_fuzzer).
  for (const auto& [key, value] :
       std::vector<std::pair<std::string, std::string>>{{"render_width", "1e30"},
                                                        {"render_height", "-1e30"},
                                                        {"render_width", "4294967376"},
                                                        {"width", "1e30"},
                                                        {"height", "3.5"}}) {
    nlohmann::json bad = legacy;
    nlohmann::json& where = key == "width" || key == "height" ? bad["keyframes"][0] : bad;
    where[key] = nlohmann::json::parse(value);
    testing::WriteTextFile(dir / "bad.json", bad.dump());
    try {
      ReadNerfstudioKeyframes(dir / "bad.json");
      FAIL() << "no error for " << key << " " << value;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  nlohmann::json wide = legacy;
  wide.erase("render_width");
  wide["keyframes"][0]["aspect"] = 1e300;
  testing::WriteTextFile(dir / "bad.json", wide.dump());
  try {
    ReadNerfstudioKeyframes(dir / "bad.json");
    FAIL() << "no error for aspect 1e300";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no usable size"), std::string::npos)
        << e.what();
  }
}

TEST(CameraPathTest, ImagesTxtRoundTripThroughColmap) {
  TempDir dir;
  const Scene scene = testing::MakeTestScene(3, 40, 30);
  CameraPathOptions o;
  o.fps = 4;
  o.smooth = false;
  const auto frames = InterpolateCameraPath(Keys(), o);
  std::filesystem::create_directories(dir / "model");
  WriteTargetImagesTxt(dir / "model/images.txt", frames);
  const auto back = ReadTargetImagesTxt(dir / "model/images.txt", scene);
  ASSERT_EQ(back.size(), frames.size());
  for (size_t j = 0; j < frames.size(); ++j) {
    EXPECT_EQ(back[j].name, frames[j].name);
    EXPECT_LT((back[j].camera.Center() - frames[j].camera.Center()).norm(), 1e-9);
    EXPECT_NEAR(back[j].camera.fx, frames[j].camera.fx, 1e-9);
  }
  // The real COLMAP reads it (text -> binary -> text) and keeps every pose.
  std::filesystem::create_directories(dir / "bin");
  std::filesystem::create_directories(dir / "txt");
  const std::string colmap = testing::RealColmapBinary();
  std::string log;
  ASSERT_EQ(testing::RunShell(colmap + " model_converter --input_path " + dir / "model" +
                                  " --output_path " + dir / "bin" + " --output_type BIN",
                              &log),
            0)
      << log;
  ASSERT_EQ(testing::RunShell(colmap + " model_converter --input_path " + dir / "bin" +
                                  " --output_path " + dir / "txt" + " --output_type TXT",
                              &log),
            0)
      << log;
  const auto converted = ReadTargetImagesTxt(dir / "txt/images.txt", scene);
  ASSERT_EQ(converted.size(), frames.size());
  // COLMAP writes the images in its own order: match them by name.
  for (const TargetCamera& c : converted) {
    const auto it = std::find_if(frames.begin(), frames.end(),
                                 [&](const TargetCamera& f) { return f.name == c.name; });
    ASSERT_NE(it, frames.end()) << c.name;
    EXPECT_LT((c.camera.Center() - it->camera.Center()).norm(), 1e-6) << c.name;
    EXPECT_LT((c.camera.R - it->camera.R).cwiseAbs().maxCoeff(), 1e-9) << c.name;
  }
}

TEST(CameraPathTest, BadOptionsAndKeysThrow) {
  CameraPathOptions o;
  o.fps = 0;
  EXPECT_THROW(o.Check(), Error);
  o = CameraPathOptions();
  o.duration_s = std::nan("");
  EXPECT_THROW(o.Check(), Error);
  EXPECT_THROW(InterpolateCameraPath({}, CameraPathOptions()), Error);
  auto keys = Keys();
  keys[2].camera.t(0) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(InterpolateCameraPath(keys, CameraPathOptions()), Error);
}

}  // namespace
}  // namespace fvs
