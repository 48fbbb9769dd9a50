// The front door end to end: `colmap view_synthesis_path` writes camera_path.json and
// images.txt; `colmap view_synthesis --camera_path ... --video` renders the frames,
// writes the per-frame report, notes that no mp4 was written without ffmpeg (FVS_FFMPEG
// set to a missing file), writes one with ffmpeg when it is installed, and resumes an
// interrupted render at the first missing frame.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "colmap_ext/image_io.h"
#include "fvs/path/video.h"
#include "scene/scene_fixture.h"
#include "scene/arc_workspace_test.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::FrontDoorBinary;
using testing::ReadTextFile;
using testing::RunShell;
using testing::TempDir;

namespace fs = std::filesystem;

class VideoCommandTest : public testing::ArcWorkspaceTest {
 protected:
  VideoCommandTest() : ArcWorkspaceTest(5, 64, 48) {}
  int Run(const std::string& args, std::string* output, const std::string& env = "") {
    return RunShell(env + " FVS_QUIET=1 " + FrontDoorBinary() + " " + args + " 2>&1",
                    output);
  }
};

TEST_F(VideoCommandTest, PathThenVideoThenResume) {
  const std::string path = dir_ / "path/camera_path.json";
  fs::create_directories(dir_ / "path");
  std::string out;
  ASSERT_EQ(Run("view_synthesis_path --workspace_path " + ws_ + " --output_path " + path +
                    " --keyframes view_000.png,view_002.png,view_004.png --fps 4"
                    " --seconds_per_keyframe 1 --images_txt " +
                    (dir_ / "path/model/images.txt"),
                &out),
            0)
      << out;
  EXPECT_NE(out.find("before"), std::string::npos) << out;
  EXPECT_NE(out.find("jerk"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir_ / "path/model/cameras.txt"));
  const auto json = nlohmann::json::parse(ReadTextFile(path));
  ASSERT_EQ(json["camera_path"].size(), 9u);
  EXPECT_EQ(json["keyframes"].size(), 3u);
  EXPECT_EQ(json["fps"].get<double>(), 4.0);

  const std::string frames = dir_ / "frames";
  const std::string render = "view_synthesis --workspace_path " + ws_ +
                             " --camera_path " + path + " --output_path " + frames +
                             " --stable_sources 1";
  ASSERT_EQ(Run(render + " --video " + (dir_ / "fly.mp4"), &out,
                "FVS_FFMPEG=/nonexistent/ffmpeg"),
            0)
      << out;
  EXPECT_NE(out.find("NOTE: ffmpeg not found"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir_ / "fly.mp4"));
  EXPECT_NE(out.find("flicker:"), std::string::npos) << out;
  for (int i = 0; i < 9; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05d.png", i);
    EXPECT_TRUE(fs::exists(frames + "/" + name)) << name;
  }
  const auto report = nlohmann::json::parse(ReadTextFile(frames + "/frame_report.json"));
  EXPECT_EQ(report["num_frames"].get<int>(), 9);
  EXPECT_EQ(report["num_rendered"].get<int>(), 9);
  EXPECT_GE(report["mean_flicker_levels"].get<double>(), 0.0);
  const std::string csv = ReadTextFile(frames + "/frame_report.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 10) << csv;

  // Interrupted: two frames lost (one missing, one truncated) -> only those are redone.
  fs::remove(frames + "/frame_00003.png");
  testing::WriteTextFile(frames + "/frame_00006.png", "\x89PNG truncated");
  const auto stamp = fs::last_write_time(frames + "/frame_00000.png");
  ASSERT_EQ(Run(render, &out), 0) << out;
  EXPECT_NE(out.find("resuming: 7 of 9"), std::string::npos) << out;
  EXPECT_EQ(fs::last_write_time(frames + "/frame_00000.png"), stamp);
  const auto resumed = nlohmann::json::parse(ReadTextFile(frames + "/frame_report.json"));
  EXPECT_EQ(resumed["num_rendered"].get<int>(), 2);
  EXPECT_EQ(resumed["num_resumed"].get<int>(), 7);
  // The earlier rows are kept (coverage known for every frame).
  EXPECT_GT(resumed["mean_coverage"].get<double>(), 0.5);
  // The chain goes on across the resumed frames: the redone frames have a flicker to
  // their (resumed) predecessors.
  const std::string rows = ReadTextFile(frames + "/frame_report.csv");
  for (const char* frame : {"frame_00003,", "frame_00006,"}) {
    const size_t at = rows.find(frame);
    ASSERT_NE(at, std::string::npos) << rows;
    const std::string row = rows.substr(at, rows.find('\n', at) - at);
    EXPECT_NE(row.find(",rendered,"), std::string::npos) << row;
    EXPECT_EQ(row.find(",-1.000000,-1.000000,"), std::string::npos) << row;
  }
  ASSERT_EQ(Run(render + " --overwrite 1", &out), 0) << out;
  EXPECT_EQ(out.find("resuming"), std::string::npos) << out;
  // Other settings into the same folder: nothing is taken from the earlier frames.
  ASSERT_EQ(Run(render + " --method nearest", &out), 0) << out;
  EXPECT_NE(out.find("settings differ"), std::string::npos) << out;
  EXPECT_EQ(out.find("resuming"), std::string::npos) << out;
  EXPECT_NE(ReadTextFile(frames + "/frame_report.json").find("\"nearest\""),
            std::string::npos);

  // The same frames through images.txt.
  ASSERT_EQ(Run("view_synthesis --workspace_path " + ws_ + " --target_images " +
                    (dir_ / "path/model/images.txt") + " --output_path " + (dir_ / "txt"),
                &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(dir_ / "txt/frame_00008.png"));
}

// Where ground truth exists, the PSNR of every frame goes beside the flicker: the
// generated scene rendered along a path by view_synthesis_synthetic --camera_path.
TEST(VideoGroundTruthTest, PsnrBesideFlickerOnTheGeneratedScene) {
  TempDir dir;
  const std::string size =
      " --SyntheticScene.num_views 8 --SyntheticScene.width 96 --SyntheticScene.height "
      "72";
  auto run = [&](const std::string& args, std::string* out) {
    return RunShell("FVS_QUIET=1 " + FrontDoorBinary() + " " + args + " 2>&1", out);
  };
  std::string out;
  ASSERT_EQ(run("view_synthesis_synthetic --output_path " + (dir / "ws") + size +
                    " --SyntheticScene.write_proxy_mesh 1",
                &out),
            0)
      << out;
  ASSERT_EQ(run("view_synthesis_path --workspace_path " + (dir / "ws") +
                    " --output_path " + (dir / "path.json") +
                    " --keyframes frame_0001.png,frame_0003.png,frame_0005.png --fps 3"
                    " --seconds_per_keyframe 1",
                &out),
            0)
      << out;
  ASSERT_EQ(run("view_synthesis_synthetic --output_path " + (dir / "gt") + size +
                    " --camera_path " + (dir / "path.json"),
                &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(dir / "gt/frame_00000.png"));
  ASSERT_EQ(run("view_synthesis --workspace_path " + (dir / "ws") + " --camera_path " +
                    (dir / "path.json") + " --output_path " + (dir / "out") +
                    " --ground_truth_path " + (dir / "gt"),
                &out),
            0)
      << out;
  const size_t at = out.find("ground truth: PSNR ");
  ASSERT_NE(at, std::string::npos) << out;
  const double psnr = std::stod(out.substr(at + 19));
  // ~26 dB measured (ulr, exact proxy, 96x72); a frame of another camera gives ~12 dB.
  EXPECT_GT(psnr, 20.0) << out;
  EXPECT_NE(out.find("flicker:"), std::string::npos) << out;
  const auto report = nlohmann::json::parse(ReadTextFile(dir / "out/frame_report.json"));
  EXPECT_EQ(report["num_frames_with_ground_truth"].get<int>(), 7);
  EXPECT_NEAR(report["mean_psnr"].get<double>(), psnr, 0.01);
  // A ground truth of another size is not the frame it claims to be.
  fs::create_directories(dir / "small");
  colmap::WriteImage(dir / "small/frame_00002.png", Image(48, 36, 3, 0.5f));
  EXPECT_NE(run("view_synthesis --workspace_path " + (dir / "ws") + " --camera_path " +
                    (dir / "path.json") + " --output_path " + (dir / "out2") +
                    " --ground_truth_path " + (dir / "small"),
                &out),
            0);
  EXPECT_NE(out.find("ground truth of 48x36 for a frame of 96x72"), std::string::npos)
      << out;
}

TEST_F(VideoCommandTest, WritesMp4WhenFfmpegIsInstalled) {
  if (FindFfmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed";
  std::string out;
  const std::string video = dir_ / "orbit.mp4";
  ASSERT_EQ(Run("view_synthesis --workspace_path " + ws_ + " --orbit 6 --output_path " +
                    (dir_ / "orbit") + " --video " + video + " --fps 6",
                &out),
            0)
      << out;
  ASSERT_TRUE(fs::exists(video)) << out;
  EXPECT_GT(fs::file_size(video), 1000u);
  std::string probe;
  // ffmpeg reads it back: 6 frames.
  ASSERT_EQ(RunShell(FindFfmpeg() + " -nostdin -v error -i " + video +
                         " -f null - 2>&1 && echo ok",
                     &probe),
            0)
      << probe;
}

TEST_F(VideoCommandTest, BadInputFailsWithOneLine) {
  std::string out;
  EXPECT_NE(Run("view_synthesis_path --workspace_path " + ws_ + " --output_path " +
                    (dir_ / "p.json") + " --keyframes nope.png",
                &out),
            0);
  EXPECT_NE(out.find("nope.png"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir_ / "p.json"));
  EXPECT_NE(Run("view_synthesis_path --workspace_path " + ws_ + " --output_path " +
                    (dir_ / "p.json") + " --fps -1",
                &out),
            0);
  EXPECT_NE(out.find("fps"), std::string::npos) << out;
  EXPECT_NE(Run("view_synthesis --workspace_path " + ws_ + " --orbit 2 --output_path " +
                    (dir_ / "o") + " --temporal_blend 1.5",
                &out),
            0);
  EXPECT_NE(out.find("temporal_blend"), std::string::npos) << out;
}

}  // namespace
}  // namespace fvs
