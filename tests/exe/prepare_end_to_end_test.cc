// view_synthesis_prepare from photos, as a user runs it: through the front door, killed
// with SIGKILL part-way, then run again. The rerun must finish the job without redoing a
// stage that had completed, a third run must skip everything, and so must a run on the
// workspace moved elsewhere. A held-out photo that SfM cannot register is a warning, and
// the evaluation lists it as skipped.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>

#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/geometry/ply.h"
#include "fvs/util/hash.h"
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

// Content hash and modification time of each of `files` (relative to `root`).
std::string Fingerprint(const std::string& root, const std::vector<std::string>& files) {
  std::string out;
  for (const std::string& f : files) {
    const std::string path = root + "/" + f;
    out += f + " " + HexHash(HashFile(path)) + " " +
           std::to_string(
               std::filesystem::last_write_time(path).time_since_epoch().count()) +
           "\n";
  }
  return out;
}

// The front door as a shell command, quiet and without a display.
std::string FrontDoorCommand() {
  return "QT_QPA_PLATFORM=offscreen FVS_QUIET=1 '" + FrontDoorBinary() + "'";
}

// Ten generated 320x240 views in `folder` (images/ and the exact model).
bool MakeTenViewScene(const std::string& colmap, const std::string& folder,
                      std::string* log) {
  return RunShell(colmap + " view_synthesis_synthetic --output_path " + folder +
                      " --SyntheticScene.num_views 10 --SyntheticScene.width 320"
                      " --SyntheticScene.height 240",
                  log) == 0;
}

TEST(PrepareEndToEnd, KilledRunResumesWithoutRedoingFinishedStages) {
  TempDir dir;
  const std::string colmap = FrontDoorCommand();
  std::string log;
  ASSERT_TRUE(MakeTenViewScene(colmap, dir / "scene", &log)) << log;
  const std::string prepare = colmap + " view_synthesis_prepare --image_path " +
                              dir / "scene/images" + " --workspace_path " + dir / "ws" +
                              " --holdout_images frame_0009.png --Refine.enabled 1";
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
  EXPECT_EQ(StagesMatching(third_log, "up to date").size(), 11u) << third_log;

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
  EXPECT_NE(ReadTextFile(dir / "ws/fvs/backdrop.json").find("\"enabled\": true"),
            std::string::npos);
  // The refinement (off by default, on here) keeps the Delaunay mesh's faces.
  const TriangleMesh refined = ReadPlyMesh(dir / "ws/meshed-refined.ply");
  EXPECT_EQ(refined.faces, mesh.faces);
  EXPECT_NE(ReadTextFile(dir / "ws/fvs/refinement.json").find("\"enabled\": true"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "ws/fvs/tmp"));

  // The workspace moved elsewhere: every stage is still up to date, and nothing changes.
  const std::vector<std::string> outputs = {
      "database.db",        "sfm/0/images.bin",      "sparse/images.bin",
      "fused.ply",          "meshed-delaunay.ply",   "fvs/depth/frame_0000.png.bin",
      "fvs/holdout.txt",    "fvs/registration.json", "fvs/backdrop.json",
      "meshed-refined.ply", "fvs/refinement.json",   "fvs/photo_quality.json"};
  const std::string before = Fingerprint(dir / "ws", outputs);
  std::filesystem::create_directories(dir / "elsewhere");
  ASSERT_EQ(RunShell("mv " + dir / "ws" + " " + dir / "elsewhere/moved"), 0);
  const std::string moved = colmap + " view_synthesis_prepare --image_path " +
                            dir / "scene/images" + " --workspace_path " +
                            dir / "elsewhere/moved" +
                            " --holdout_images frame_0009.png --Refine.enabled 1";
  std::string moved_log;
  ASSERT_EQ(RunShell(moved, &moved_log), 0) << moved_log;
  EXPECT_EQ(StagesMatching(moved_log, "up to date").size(), 11u) << moved_log;
  EXPECT_TRUE(StagesMatching(moved_log, "done in").empty()) << moved_log;
  EXPECT_EQ(Fingerprint(dir / "elsewhere/moved", outputs), before);
  EXPECT_EQ(ReadTextFile(dir / "elsewhere/moved/fvs/manifest.json").find(dir.path()),
            std::string::npos)
      << "the manifest holds absolute paths";
}

// A held-out photo that SfM does not register (a featureless gradient among the
// generated views) is a warning: prepare finishes, reports 10 of 11 registered, and the
// evaluation evaluates the other held-out view and lists this one as skipped.
TEST(PrepareEndToEnd, UnregisteredHoldoutIsAWarningAndEvaluationSkipsIt) {
  TempDir dir;
  const std::string colmap = FrontDoorCommand();
  std::string log;
  ASSERT_TRUE(MakeTenViewScene(colmap, dir / "scene", &log)) << log;
  Image gradient(320, 240, 3);
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; ++x) {
      for (int c = 0; c < 3; ++c) gradient.at(x, y, c) = 0.2f + 0.5f * x / 320.0f;
    }
  }
  colmap::WriteImage(dir / "scene/images/zz_blank.png", gradient);
  ASSERT_EQ(RunShell(colmap + " view_synthesis_prepare --image_path " +
                         dir / "scene/images" + " --workspace_path " + dir / "ws" +
                         " --holdout_images frame_0008.png,zz_blank.png 2>&1",
                     &log),
            0)
      << log;
  EXPECT_NE(log.find("WARNING: holdout image 'zz_blank.png' was not registered by SfM"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("registered 10 of 11 images"), std::string::npos) << log;
  const auto report =
      nlohmann::json::parse(ReadTextFile(dir / "ws/fvs/registration.json"));
  EXPECT_EQ(report["images"].get<int>(), 11);
  EXPECT_EQ(report["registered"].get<int>(), 10);
  EXPECT_EQ(report["unregistered"], nlohmann::json::array({"zz_blank.png"}));
  EXPECT_EQ(report["matcher"].get<std::string>(), "exhaustive");
  EXPECT_TRUE(std::filesystem::exists(dir / "ws/meshed-delaunay.ply"));

  ASSERT_EQ(RunShell(colmap + " view_synthesis_eval --workspace_path " + dir / "ws" +
                         " --output_path " + dir / "eval" + " 2>&1",
                     &log),
            0)
      << log;
  const std::string csv = ReadTextFile(dir / "eval/results.csv");
  const size_t blank = csv.find(",zz_blank.png,");
  ASSERT_NE(blank, std::string::npos) << csv;
  const std::string row = csv.substr(blank, csv.find('\n', blank) - blank);
  EXPECT_NE(row.find(",skipped,"), std::string::npos) << row;
  EXPECT_NE(row.find("not registered by SfM"), std::string::npos) << row;
  const size_t held = csv.find(",frame_0008.png,");
  ASSERT_NE(held, std::string::npos) << csv;
  EXPECT_NE(csv.substr(held, csv.find('\n', held) - held).find(",ok,"), std::string::npos)
      << csv;
  EXPECT_NE(ReadTextFile(dir / "eval/results.md").find("not registered by SfM"),
            std::string::npos);
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
  // All-black photos (issue 39 item 6): COLMAP's mapper only says it "failed to create
  // sparse model"; prepare says why.
  std::filesystem::create_directories(dir / "black");
  for (const char* name : {"a.png", "b.png", "c.png", "d.png"}) {
    colmap::WriteImage(dir / "black/" + name, Image(160, 120, 3));
  }
  EXPECT_EQ(RunShell(colmap + " view_synthesis_prepare --image_path " + dir / "black" +
                         " --workspace_path " + dir / "ws_black",
                     &log),
            1);
  EXPECT_NE(log.find("ERROR: " + dir / "black" +
                     ": SfM registered no photos: 4 of 4 photos have fewer than 100 SIFT "
                     "features"),
            std::string::npos)
      << log;
}

}  // namespace
}  // namespace fvs::testing
