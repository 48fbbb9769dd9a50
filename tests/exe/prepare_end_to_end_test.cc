// view_synthesis_prepare from photos, as a user runs it: through the front door, killed
// with SIGKILL part-way, then run again. The rerun must finish the job without redoing a
// stage that had completed, and a third run must skip everything.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>

#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/ply.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

std::set<std::string> StagesMatching(const std::string& log, const std::string& suffix) {
  std::set<std::string> stages;
  const std::regex re("\\] ([a-z_]+): " + suffix);
  for (auto it = std::sregex_iterator(log.begin(), log.end(), re);
       it != std::sregex_iterator(); ++it) {
    stages.insert((*it)[1]);
  }
  return stages;
}

TEST(PrepareEndToEnd, KilledRunResumesWithoutRedoingFinishedStages) {
  TempDir dir;
  const std::string colmap =
      "QT_QPA_PLATFORM=offscreen FVS_QUIET=1 '" + FrontDoorBinary() + "'";
  std::string log;
  ASSERT_EQ(RunShell(colmap + " view_synthesis_synthetic --output_path " + dir / "scene" +
                         " --SyntheticScene.num_views 10 --SyntheticScene.width 320"
                         " --SyntheticScene.height 240",
                     &log),
            0)
      << log;
  const std::string prepare = colmap + " view_synthesis_prepare --image_path " +
                              dir / "scene/images" + " --workspace_path " + dir / "ws" +
                              " --holdout_images frame_0009.png";
  // SIGKILL part-way: 25 s is inside SfM or stereo on 2 cores.
  std::string killed_log;
  RunShell("timeout -s KILL 25 " + prepare, &killed_log);
  const std::set<std::string> finished_before_kill =
      StagesMatching(killed_log, "done in");

  std::string resumed_log;
  ASSERT_EQ(RunShell(prepare, &resumed_log), 0) << killed_log << resumed_log;
  const std::set<std::string> skipped = StagesMatching(resumed_log, "up to date");
  for (const std::string& stage : finished_before_kill) {
    EXPECT_TRUE(skipped.count(stage)) << stage << " was redone:\n" << resumed_log;
  }

  std::string third_log;
  ASSERT_EQ(RunShell(prepare, &third_log), 0) << third_log;
  EXPECT_EQ(StagesMatching(third_log, "up to date").size(), 8u) << third_log;

  // The workspace is a COLMAP dense workspace with a mesh; the held-out image is
  // registered but has no depth map and is in no stereo config.
  const auto rec = colmap::ReadSparseModel(dir / "ws/sparse");
  EXPECT_EQ(rec.images.size(), 10u);
  EXPECT_NE(rec.FindImageByName("frame_0009.png"), nullptr);
  EXPECT_FALSE(
      std::filesystem::exists(dir / "ws/stereo/depth_maps/frame_0009.png.geometric.bin"));
  EXPECT_TRUE(
      std::filesystem::exists(dir / "ws/stereo/depth_maps/frame_0000.png.geometric.bin"));
  EXPECT_EQ(ReadTextFile(dir / "ws/stereo/fusion.cfg").find("frame_0009"),
            std::string::npos);
  const TriangleMesh mesh = ReadPlyMesh(dir / "ws/meshed-delaunay.ply");
  EXPECT_GT(mesh.faces.size(), 1000u);
  EXPECT_TRUE(std::filesystem::exists(dir / "ws/fvs/depth/frame_0000.png.bin"));
  EXPECT_FALSE(std::filesystem::exists(dir / "ws/fvs/tmp"));
}

TEST(PrepareEndToEnd, BadInputIsOneLine) {
  TempDir dir;
  const std::string colmap = "FVS_QUIET=1 '" + FrontDoorBinary() + "'";
  std::string log;
  EXPECT_NE(RunShell(colmap + " view_synthesis_prepare --image_path " + dir / "nothing" +
                         " --workspace_path " + dir / "ws",
                     &log),
            0);
  EXPECT_NE(log.find("ERROR: "), std::string::npos) << log;
  EXPECT_NE(log.find("image folder does not exist"), std::string::npos) << log;
  std::filesystem::create_directories(dir / "two");
  WriteTextFile(dir / "two/a.png", "x");
  WriteTextFile(dir / "two/b.png", "x");
  EXPECT_NE(RunShell(colmap + " view_synthesis_prepare --image_path " + dir / "two" +
                         " --workspace_path " + dir / "ws",
                     &log),
            0);
  EXPECT_NE(log.find("at least 3"), std::string::npos) << log;
}

}  // namespace
}  // namespace fvs::testing
