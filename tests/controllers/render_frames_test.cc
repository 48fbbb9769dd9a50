// The frame loop that `colmap view_synthesis` and the GUI's path render share
// (controllers/render_frames.h), on the in-memory test world: every frame written with
// its report row, resumed frames keeping their earlier rows, cancellation between frames.
#include "fvs/controllers/render_frames.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "fvs/render/method.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::ArcCamera;
using testing::MakeTestScene;
using testing::TempDir;

std::vector<RenderFrame> ArcFrames(int n) {
  std::vector<RenderFrame> frames;
  for (int i = 0; i < n; ++i) {
    RenderFrame frame;
    frame.target.name = FrameName(i);
    frame.target.camera = ArcCamera(-0.5 + 0.1 * i, 48, 36);
    frames.push_back(frame);
  }
  return frames;
}

TEST(RenderFrames, WritesEveryFrameAndItsReportRow) {
  const Scene scene = MakeTestScene(5, 48, 36);
  TempDir dir;
  RenderFramesOptions options;
  options.output_path = dir.path();
  options.method = "ulr";
  options.report_stem = dir / "frame_report";
  std::unique_ptr<Method> method = CreateMethod("ulr", {});
  std::vector<size_t> before;
  RenderFramesCallbacks callbacks;
  callbacks.before_frame = [&](size_t i) { before.push_back(i); };
  const RenderFramesResult result =
      RenderFrames(scene, method.get(), ArcFrames(3), options, callbacks);
  EXPECT_EQ(before, (std::vector<size_t>{0, 1, 2}));
  ASSERT_EQ(result.rendered.size(), 3u);
  ASSERT_EQ(result.report.size(), 3u);
  EXPECT_EQ(result.summary.num_rendered, 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(std::filesystem::exists(dir / (FrameName(i) + ".png")));
    EXPECT_EQ(result.report[i].status, "rendered");
    EXPECT_GT(result.report[i].coverage, 0.5);
  }
  // The chain measured flicker from the second frame on.
  EXPECT_LT(result.report[0].flicker, 0);
  EXPECT_GE(result.report[1].flicker, 0);
  EXPECT_EQ(ReadFrameReport(dir / "frame_report.csv").size(), 3u);
}

TEST(RenderFrames, ResumedFramesKeepTheirRowsAndTheChainGoesOn) {
  const Scene scene = MakeTestScene(5, 48, 36);
  TempDir dir;
  RenderFramesOptions options;
  options.output_path = dir.path();
  options.method = "ulr";
  options.report_stem = dir / "frame_report";
  std::unique_ptr<Method> method = CreateMethod("ulr", {});
  std::vector<RenderFrame> frames = ArcFrames(3);
  RenderFrames(scene, method.get(), frames, options);
  options.earlier = ReadFrameReport(dir / "frame_report.csv");
  frames[0].done = true;
  frames[1].done = true;
  const RenderFramesResult result = RenderFrames(scene, method.get(), frames, options);
  ASSERT_EQ(result.report.size(), 3u);
  EXPECT_EQ(result.report[0].status, "resumed");
  EXPECT_EQ(result.report[1].status, "resumed");
  EXPECT_EQ(result.report[1].sources, options.earlier.at(FrameName(1)).sources);
  ASSERT_EQ(result.rendered.size(), 1u);
  EXPECT_EQ(result.rendered[0].index, 2u);
  // Frame 1 was restored from disk: frame 2 still has a predecessor to compare with.
  EXPECT_GE(result.report[2].flicker, 0);
}

TEST(RenderFrames, StopsBetweenFramesWhenCancelledAndWritesNoReportWithoutAStem) {
  const Scene scene = MakeTestScene(5, 48, 36);
  TempDir dir;
  RenderFramesOptions options;
  options.output_path = dir.path();
  options.method = "ulr";
  std::unique_ptr<Method> method = CreateMethod("ulr", {});
  int rendered = 0;
  RenderFramesCallbacks callbacks;
  callbacks.cancelled = [&] { return rendered >= 1; };
  callbacks.after_frame = [&](size_t) { ++rendered; };
  const RenderFramesResult result =
      RenderFrames(scene, method.get(), ArcFrames(3), options, callbacks);
  EXPECT_EQ(result.rendered.size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(dir / (FrameName(0) + ".png")));
  EXPECT_FALSE(std::filesystem::exists(dir / (FrameName(1) + ".png")));
  EXPECT_FALSE(std::filesystem::exists(dir / "frame_report.csv"));
}

TEST(RenderFrames, FlickerIsLeftUnmeasuredWhenNotAskedFor) {
  const Scene scene = MakeTestScene(5, 48, 36);
  TempDir dir;
  RenderFramesOptions options;
  options.output_path = dir.path();
  options.method = "ulr";
  options.temporal.measure_flicker = false;  // the GUI's path render
  std::unique_ptr<Method> method = CreateMethod("ulr", {});
  const RenderFramesResult result =
      RenderFrames(scene, method.get(), ArcFrames(2), options);
  ASSERT_EQ(result.report.size(), 2u);
  EXPECT_LT(result.report[1].flicker, 0);
  EXPECT_GE(result.report[1].source_changes, 0);  // the chain itself goes on
}

TEST(RenderFrames, AnInvalidCameraFailsAtItsFrameAfterTheFramesBefore) {
  const Scene scene = MakeTestScene(5, 48, 36);
  TempDir dir;
  RenderFramesOptions options;
  options.output_path = dir.path();
  options.method = "ulr";
  std::unique_ptr<Method> method = CreateMethod("ulr", {});
  std::vector<RenderFrame> frames = ArcFrames(2);
  frames[1].target.camera.width = 0;
  EXPECT_THROW(RenderFrames(scene, method.get(), frames, options), Error);
  EXPECT_TRUE(std::filesystem::exists(dir / (FrameName(0) + ".png")));
}

}  // namespace
}  // namespace fvs
