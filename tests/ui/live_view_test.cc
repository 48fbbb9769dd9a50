// The live view's logic without a window (ui/live_view.h): the scale controller, the
// levels of a pose, the renderer's frames in order, a newer pose dropping an older one's
// sharpening, and the complete frame against `colmap view_synthesis` at the same pose.
#include "ui/live_view.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "colmap_ext/image_io.h"
#include "fvs/path/camera_path.h"
#include "fvs/util/cancel.h"
#include "fvs/util/parallel.h"
#include "support/test_support.h"
#include "ui/ui_test_scene.h"
#include "ui/workspace_contents.h"

namespace fvs::ui {
namespace {

using testing::FrontDoorBinary;
using testing::RunShell;
using testing::TempDir;

TEST(CancelScopeTest, ParallelForStopsAtTheNextIndexOnceTheFlagIsSet) {
  std::atomic<bool> flag{false};
  std::atomic<int> calls{0};
  const CancelScope scope(&flag);
  EXPECT_THROW(ParallelFor(
                   0, 1000,
                   [&](int64_t i) {
                     ++calls;
                     if (i == 10) flag = true;
                   },
                   1),
               Cancelled);
  EXPECT_EQ(calls.load(), 11);
  // Nested calls on the threads a ParallelFor starts see the flag too.
  flag = false;
  calls = 0;
  EXPECT_THROW(ParallelFor(
                   0, 2,
                   [&](int64_t) {
                     ParallelFor(
                         0, 1000,
                         [&](int64_t j) {
                           ++calls;
                           if (j == 5) flag = true;
                         },
                         1);
                   },
                   2),
               Cancelled);
  EXPECT_LT(calls.load(), 100);
  // Without a scope nothing is cancelled.
  {
    const CancelScope none(nullptr);
    int n = 0;
    ParallelFor(
        0, 100, [&](int64_t) { ++n; }, 1);
    EXPECT_EQ(n, 100);
  }
}

TEST(LiveScaleTest, HoldsTheFrameTimeWithinItsBounds) {
  LiveViewOptions options;
  options.min_fps = 20;  // 0.035 s per frame at the 0.7 headroom
  LiveScale scale(options);
  EXPECT_DOUBLE_EQ(scale.scale(), options.initial_scale);
  scale.Observe(scale.scale(), 0.2);  // far too slow: shrinks, damped to 0.7x
  EXPECT_NEAR(scale.scale(), 0.7 * options.initial_scale, 1e-12);
  for (int i = 0; i < 100; ++i) scale.Observe(scale.scale(), 10.0);
  EXPECT_DOUBLE_EQ(scale.scale(), options.min_scale);
  for (int i = 0; i < 100; ++i) scale.Observe(scale.scale(), 1e-6);
  EXPECT_DOUBLE_EQ(scale.scale(), options.max_live_scale);
  // Within the dead band nothing changes.
  const double before = scale.scale();
  scale.Observe(before, 0.7 / 20 * 1.02);
  EXPECT_DOUBLE_EQ(scale.scale(), before);
  // A frame time that grows with the pixels settles where it meets the budget.
  for (int i = 0; i < 200; ++i) {
    const double s = scale.scale();
    scale.Observe(s, 0.4 * s * s);  // 0.4 s at full size
  }
  EXPECT_NEAR(0.4 * scale.scale() * scale.scale(), 0.035, 0.035 * 0.12);

  options.min_scale = 0;
  EXPECT_THROW(options.Check(), Error);
}

TEST(LiveLevelsTest, DoublesUpToTheFinalRequestAtFullSize) {
  LiveViewOptions options;
  NovelViewOptions final_request;
  final_request.method = "ulr";
  final_request.num_sources = 6;
  const auto levels = LiveLevels(0.2, 1000, 500, final_request, options);
  ASSERT_EQ(levels.size(), 3u);  // 0.2, 0.4, full (0.8 would cost nearly as much)
  EXPECT_EQ(levels[0].request.width, 200);
  EXPECT_EQ(levels[0].request.height, 100);
  EXPECT_EQ(levels[0].request.num_sources, options.live_max_sources);  // cheaper live
  EXPECT_EQ(levels[1].request.width, 400);
  EXPECT_EQ(levels[1].request.num_sources, 6);  // then the final K
  EXPECT_EQ(levels[2].request.width, 1000);
  EXPECT_EQ(levels[2].request.height, 500);
  EXPECT_DOUBLE_EQ(levels[2].scale, 1.0);
  // 0.1, 0.2, 0.4, full.
  EXPECT_EQ(LiveLevels(0.1, 1000, 500, final_request, options).size(), 4u);
  // A network method sharpens with ulr and comes at full size only.
  final_request.method = "fvs";
  final_request.model_path = "w.safetensors";
  const auto network = LiveLevels(0.3, 1000, 500, final_request, options);
  ASSERT_EQ(network.size(), 3u);  // 0.3, 0.6, full
  EXPECT_EQ(network[0].request.method, "ulr");
  EXPECT_TRUE(network[1].request.model_path.empty());
  EXPECT_EQ(network[2].request.method, "fvs");
  EXPECT_EQ(network[2].request.model_path, "w.safetensors");
}

class LiveRendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    GenerateUiTestScene(dir_->path(), 11, 320, 240);
    contents_ = new WorkspaceContents(LoadWorkspace(dir_->path()));
  }
  static void TearDownTestSuite() {
    delete contents_;
    delete dir_;
  }
  // A viewpoint between registered cameras 2 and 3.
  static PinholeCamera Between(int width, int height) {
    PinholeCamera c = TargetCameraFor(contents_->cameras[2], width, height);
    c.t = 0.5 * (contents_->cameras[2].t + contents_->cameras[3].t);
    return c;
  }

  struct Collected {
    std::mutex mutex;
    std::vector<std::shared_ptr<const LiveFrame>> frames;
    std::vector<std::string> errors;
    bool Complete(uint64_t id) {
      std::lock_guard<std::mutex> lock(mutex);
      for (const auto& f : frames)
        if (f->pose_id == id && f->complete()) return true;
      return false;
    }
  };
  static std::unique_ptr<LiveRenderer> Start(Collected* out,
                                             LiveViewOptions options = {}) {
    return std::make_unique<LiveRenderer>(
        contents_->scene, options,
        [out](std::shared_ptr<const LiveFrame> f) {
          std::lock_guard<std::mutex> lock(out->mutex);
          out->frames.push_back(f);
        },
        [out](const std::string& e) {
          std::lock_guard<std::mutex> lock(out->mutex);
          out->errors.push_back(e);
        });
  }
  static bool WaitFor(const std::function<bool()>& done, double seconds = 120) {
    const auto end =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }

  static TempDir* dir_;
  static WorkspaceContents* contents_;
};
TempDir* LiveRendererTest::dir_ = nullptr;
WorkspaceContents* LiveRendererTest::contents_ = nullptr;

TEST_F(LiveRendererTest, SharpensToTheCommandLinesRender) {
  ASSERT_TRUE(contents_->can_render()) << contents_->render_error;
  Collected out;
  auto live = Start(&out);
  const PinholeCamera camera = Between(320, 240);
  NovelViewOptions final_request;  // ulr, K auto
  const uint64_t id = live->Request(camera, final_request);
  ASSERT_TRUE(WaitFor([&] { return out.Complete(id); }));
  std::lock_guard<std::mutex> lock(out.mutex);
  ASSERT_TRUE(out.errors.empty()) << out.errors.front();
  ASSERT_GE(out.frames.size(), 2u);
  // Level after level, each larger, the live frame first.
  for (size_t i = 0; i < out.frames.size(); ++i) {
    EXPECT_EQ(out.frames[i]->level, static_cast<int>(i));
    if (i > 0) {
      EXPECT_GT(out.frames[i]->view.camera.width, out.frames[i - 1]->view.camera.width);
    }
    EXPECT_GE(out.frames[i]->seconds_since_request, out.frames[i]->view.seconds);
  }
  const LiveFrame& complete = *out.frames.back();
  EXPECT_EQ(complete.view.camera.width, 320);
  EXPECT_EQ(complete.view.camera.height, 240);
  // The live frame is smaller.
  const Image& live_frame = out.frames.front()->view.result.color;
  EXPECT_LT(live_frame.width, 320);

  // Exactly the library's render of that pose...
  const RenderedView direct = RenderNovelView(*contents_->scene, camera, final_request);
  ASSERT_EQ(direct.result.color.data.size(), complete.view.result.color.data.size());
  double max_diff = 0;
  for (size_t i = 0; i < direct.result.color.data.size(); ++i)
    max_diff = std::max<double>(max_diff, std::abs(direct.result.color.data[i] -
                                                   complete.view.result.color.data[i]));
  EXPECT_EQ(max_diff, 0.0);

  // ...and what `colmap view_synthesis` writes for it, through a camera path file (its
  // poses and field of view round-trip through text: allowed one 8-bit level).
  TempDir work;
  const std::string path = work.path() + "/camera_path.json";
  TargetCamera frame;
  frame.name = "frame_00000";
  frame.camera = contents_->ToWorld(camera);
  CameraPathOptions path_options;
  WriteNerfstudioCameraPath(path, {{"view", frame.camera}}, {frame}, path_options);
  std::string output;
  ASSERT_EQ(RunShell(FrontDoorBinary() + " view_synthesis --workspace_path " +
                         dir_->path() + " --camera_path " + path + " --output_path " +
                         work.path() + "/out --method ulr",
                     &output),
            0)
      << output;
  const Image cli = colmap::ReadImage(work.path() + "/out/frame_00000.png");
  ASSERT_EQ(cli.width, 320);
  ASSERT_EQ(cli.height, 240);
  int64_t off = 0;
  double sum = 0;
  for (size_t i = 0; i < cli.data.size(); ++i) {
    const double d = std::abs(
        cli.data[i] - std::round(complete.view.result.color.data[i] * 255.f) / 255.f);
    sum += d;
    off += d > 1.5 / 255;
  }
  std::printf(
      "complete frame vs colmap view_synthesis: mean |diff| %.2g, %lld of %zu values "
      "over one level\n",
      sum / cli.data.size(), static_cast<long long>(off), cli.data.size());
  EXPECT_LT(sum / cli.data.size(), 0.5 / 255);
  EXPECT_LT(off, static_cast<int64_t>(cli.data.size() / 1000));
}

TEST_F(LiveRendererTest, ANewPoseDropsTheSharpeningOfTheOldOne) {
  Collected out;
  LiveViewOptions options;
  options.settle_seconds = 0;
  auto live = Start(&out, options);
  // A large final size, so that sharpening takes a while.
  const PinholeCamera a = Between(1600, 1200);
  PinholeCamera b = a;
  b.t += Eigen::Vector3d(0.05, 0, 0);
  const uint64_t id_a = live->Request(a, NovelViewOptions());
  ASSERT_TRUE(WaitFor([&] {
    std::lock_guard<std::mutex> lock(out.mutex);
    return !out.frames.empty() && out.frames.back()->level >= 1;
  }));
  const uint64_t id_b = live->Request(b, NovelViewOptions());
  size_t seen_at_b;
  {
    std::lock_guard<std::mutex> lock(out.mutex);
    seen_at_b = out.frames.size();
  }
  ASSERT_TRUE(WaitFor([&] { return out.Complete(id_b); }));
  std::lock_guard<std::mutex> lock(out.mutex);
  EXPECT_TRUE(out.errors.empty());
  for (size_t i = seen_at_b; i < out.frames.size(); ++i) {
    EXPECT_EQ(out.frames[i]->pose_id, id_b) << "frame " << i << " of the old pose";
  }
  for (const auto& f : out.frames) EXPECT_FALSE(f->pose_id == id_a && f->complete());
  std::printf("renders dropped: %d\n", live->num_dropped());

  // A pause drops the work in flight and renders nothing more.
  live->Pause();
}

TEST_F(LiveRendererTest, ARenderUnderASetFlagIsCancelled) {
  std::atomic<bool> flag{true};
  const CancelScope scope(&flag);
  EXPECT_THROW(RenderNovelView(*contents_->scene, Between(320, 240), NovelViewOptions()),
               Cancelled);
}

}  // namespace
}  // namespace fvs::ui
