// The resume guard of `colmap view_synthesis --video` keys the weights, the workspace and
// the targets by content: weights retrained to the same path never reuse old frames,
// while a rerun with the same bytes (whatever their modification times) resumes.
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "colmap_ext/image_io.h"
#include "fvs/net/net.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;
using testing::FrontDoorBinary;
using testing::ReadTextFile;
using testing::RunShell;

// Random fvs_fast weights from `seed`, written to `path`.
void SaveRandomWeights(const std::string& path, int seed) {
  torch::manual_seed(seed);
  const ModelConfig config = ModelConfig::ForVariant("fvs_fast");
  FvsNet net(config);
  SaveWeights(net, config, path, /*fp16=*/false);
}

// (rendered, resumed) frames of the last run, from its frame report.
std::pair<int, int> RenderedAndResumed(const std::string& frames) {
  const auto json = nlohmann::json::parse(ReadTextFile(frames + "/frame_report.json"));
  return {json["num_rendered"].get<int>(), json["num_resumed"].get<int>()};
}

TEST(RenderResume, KeysWeightsWorkspaceAndTargetsByContent) {
  testing::TempDir dir;
  const std::string ws = dir / "ws";
  testing::WriteTestWorkspace(ws, testing::ArcViews(4, 48, 36),
                              testing::MakeTestWorldMesh());
  const std::string weights = dir / "weights.safetensors";
  SaveRandomWeights(weights, 7);
  const std::string frames = dir / "frames";
  const std::string render =
      "OMP_WAIT_POLICY=PASSIVE FVS_QUIET=1 FVS_FFMPEG=/nonexistent/ffmpeg " +
      FrontDoorBinary() + " view_synthesis --workspace_path " + ws +
      " --orbit 3 --method fvs --num_sources 2 --num_threads 2 --model_path " + weights +
      " --output_path " + frames + " --video " + (dir / "orbit.mp4") + " 2>&1";
  std::string out;
  ASSERT_EQ(RunShell(render, &out), 0) << out;
  EXPECT_EQ(RenderedAndResumed(frames), std::make_pair(3, 0)) << out;
  ASSERT_EQ(RunShell(render, &out), 0) << out;
  EXPECT_EQ(RenderedAndResumed(frames), std::make_pair(0, 3)) << out;

  // Retrained weights at the same path: every frame is rendered again.
  const std::string before = ReadTextFile(weights);
  SaveRandomWeights(weights, 8);
  ASSERT_NE(ReadTextFile(weights), before);
  ASSERT_EQ(RunShell(render, &out), 0) << out;
  EXPECT_NE(out.find("settings differ"), std::string::npos) << out;
  EXPECT_EQ(RenderedAndResumed(frames), std::make_pair(3, 0)) << out;
  ASSERT_EQ(RunShell(render, &out), 0) << out;
  EXPECT_EQ(RenderedAndResumed(frames), std::make_pair(0, 3)) << out;

  // The same bytes with new times (a copy, a touch) still resume.
  const auto later = fs::file_time_type::clock::now() + std::chrono::hours(1);
  fs::last_write_time(weights, later);
  fs::last_write_time(ws + "/meshed-delaunay.ply", later);
  ASSERT_EQ(RunShell(render, &out), 0) << out;
  EXPECT_EQ(RenderedAndResumed(frames), std::make_pair(0, 3)) << out;

  // Another photo in the workspace (same name and size): rendered again.
  Image photo = colmap::ReadImage(ws + "/images/view_001.png", 3);
  photo.at(5, 5, 0) = photo.at(5, 5, 0) > 0.5f ? 0.0f : 1.0f;
  colmap::WriteImage(ws + "/images/view_001.png", photo);
  ASSERT_EQ(RunShell(render, &out), 0) << out;
  EXPECT_EQ(RenderedAndResumed(frames), std::make_pair(3, 0)) << out;
}

}  // namespace
}  // namespace fvs
