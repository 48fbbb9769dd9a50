// The render and evaluation jobs called as the GUI or another program would, without the
// front door: RunRenderTargets renders, then resumes, an orbit of a written workspace;
// RunEvaluation scores a leave-one-out protocol and writes its reports. Their options
// fail with one line before anything is written.
#include <gtest/gtest.h>

#include <filesystem>

#include "fvs/controllers/evaluation.h"
#include "fvs/controllers/render_targets.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::ArcViews;
using testing::MakeTestWorldMesh;
using testing::ScopedEnv;
using testing::TempDir;

namespace fs = std::filesystem;

TEST(Jobs, RenderTargetsRendersThenResumes) {
  ScopedEnv quiet("FVS_QUIET", "1");
  TempDir dir;
  testing::WriteTestWorkspace(dir / "ws", ArcViews(5, 48, 36), MakeTestWorldMesh());
  RenderTargetsOptions options;
  options.workspace_path = dir / "ws";
  options.output_path = dir / "out";
  options.orbit = 3;
  options.render.num_threads = 2;
  const RenderTargetsResult first = RunRenderTargets(options);
  EXPECT_EQ(first.num_views, 5);
  ASSERT_EQ(first.target_names.size(), 3u);
  EXPECT_EQ(first.frames.rendered.size(), 3u);
  for (const std::string& name : first.target_names) {
    EXPECT_TRUE(fs::exists(dir / ("out/" + name + ".png"))) << name;
  }
  EXPECT_TRUE(fs::exists(dir / "out/render_settings.json"));
  EXPECT_TRUE(fs::exists(dir / "out/frame_report.csv"));

  fs::remove(dir / ("out/" + first.target_names[2] + ".png"));
  const RenderTargetsResult second = RunRenderTargets(options);
  ASSERT_EQ(second.frames.rendered.size(), 1u);
  EXPECT_EQ(second.frames.rendered[0].index, 2u);
  EXPECT_EQ(second.frames.summary.num_resumed, 2);
}

TEST(Jobs, RenderTargetsOptionsFailBeforeAnythingIsWritten) {
  TempDir dir;
  RenderTargetsOptions options;
  options.workspace_path = dir / "ws";
  options.output_path = dir / "out";
  options.orbit = 2;
  options.interpolate = 2;
  testing::ExpectError([&] { RunRenderTargets(options); }, {"exactly one of"});
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(Jobs, EvaluationScoresEveryTargetAndWritesItsReports) {
  ScopedEnv quiet("FVS_QUIET", "1");
  ScopedEnv no_lpips("FVS_LPIPS_PATH", nullptr);
  TempDir dir;
  testing::WriteTestWorkspace(dir / "ws", ArcViews(5, 48, 36), MakeTestWorldMesh());
  EvaluationOptions options;
  options.workspace_path = dir / "ws";
  options.output_path = dir / "eval";
  options.protocol.protocol = "leave_one_out";
  options.protocol.every = 2;
  options.render.num_threads = 2;
  const EvaluationResult result = RunEvaluation(options);
  ASSERT_EQ(result.targets.size(), 3u);
  ASSERT_EQ(result.results.size(), 3u);
  ASSERT_EQ(result.summary.size(), 1u);
  EXPECT_EQ(result.summary[0].views_ok, 3);
  EXPECT_GT(result.results[0].psnr, 15);
  EXPECT_EQ(result.scene_name, "ws");
  for (const char* file :
       {"results.csv", "summary.csv", "results.md", "machine.txt", "contact_sheet.png"}) {
    EXPECT_TRUE(fs::exists(dir / (std::string("eval/") + file))) << file;
  }
  EXPECT_FALSE(fs::exists(dir / "eval/error_vs_time.png"));  // one configuration
  RequireNoFailedViews(options, result);                     // does not throw
}

TEST(Jobs, EvaluationOptionsFailBeforeTheSceneLoads) {
  TempDir dir;
  EvaluationOptions options;
  options.workspace_path = dir / "missing";
  options.output_path = dir / "eval";
  options.config.scale = 5;
  testing::ExpectError([&] { RunEvaluation(options); }, {"--scale"});
  options.config.scale = 1;
  options.config.method = "no_such_method";
  EXPECT_THROW(RunEvaluation(options), Error);
  EXPECT_FALSE(fs::exists(dir / "eval"));
}

}  // namespace
}  // namespace fvs
