// Source selection on the in-memory test world: ranking by overlap, exclusion, depth
// tolerance, sources that see nothing, K larger than the scene, threads not changing
// results.
#include "fvs/scene/source_selection.h"

#include <gtest/gtest.h>

#include "fvs/util/error.h"
#include "scene/scene_fixture.h"

namespace fvs {
namespace {

using testing::ArcCamera;
using testing::MakeTestScene;

TEST(SourceSelectionTest, RanksTheCoincidentViewFirstAndSkipsExcluded) {
  const Scene scene = MakeTestScene(6, 64, 48);
  for (int target = 0; target < scene.num_views(); ++target) {
    const PinholeCamera& cam = scene.view(target).camera;
    const Image depth = scene.RenderDepth(cam);
    int64_t surface = 0;
    for (float d : depth.data) surface += d > 0;
    const auto scores = SelectSources(scene, cam, depth, 3);
    ASSERT_EQ(scores.size(), 3u);
    EXPECT_EQ(scores[0].view_index, target);
    EXPECT_EQ(scores[0].count, surface);
    EXPECT_DOUBLE_EQ(scores[0].fraction, 1.0);
    for (size_t i = 1; i < scores.size(); ++i) {
      EXPECT_LE(scores[i].count, scores[i - 1].count);
      EXPECT_GT(scores[i].count, 0);
    }
    SourceSelectionOptions options;
    options.k = 2;
    options.exclude = {target};
    const auto held_out = SelectSources(scene, cam, depth, options);
    ASSERT_EQ(held_out.size(), 2u);
    for (const auto& s : held_out) EXPECT_NE(s.view_index, target);
    // Neighbours on the arc overlap most.
    EXPECT_EQ(std::abs(held_out[0].view_index - target), 1);
  }
}

TEST(SourceSelectionTest, NeverReturnsSourcesThatSeeNothingEvenForLargeK) {
  Scene scene = MakeTestScene(3, 48, 36);
  // A target looking at the wall behind every source (the arc faces -x).
  const PinholeCamera away =
      testing::LookAtCamera(Eigen::Vector3d(3, 0, 1.5) - scene.origin(),
                            Eigen::Vector3d(6, 0, 1.5) - scene.origin(), 48, 36);
  const Image depth = scene.RenderDepth(away);
  EXPECT_TRUE(SelectSources(scene, away, depth, 10).empty());
  // K larger than the scene: all seeing sources, no more.
  const PinholeCamera& cam = scene.view(1).camera;
  const auto all = SelectSources(scene, cam, scene.RenderDepth(cam), 50);
  EXPECT_EQ(all.size(), 3u);
  // No surface at all (depth 0 everywhere).
  EXPECT_TRUE(SelectSources(scene, cam, Image(48, 36, 1, 0.f), 5).empty());
}

TEST(SourceSelectionTest, DepthToleranceDecidesWhatCounts) {
  PinholeCamera cam;
  cam.width = 20;
  cam.height = 10;
  cam.fx = cam.fy = 20;
  cam.cx = 10;
  cam.cy = 5;
  const Image target_depth(20, 10, 1, 4.f);
  const Image source_depth(20, 10, 1, 4.f * 1.05f);  // 5% behind what the target sees
  EXPECT_EQ(CountVisibleTargetPixels(cam, target_depth, cam, source_depth, 0.10), 200);
  EXPECT_EQ(CountVisibleTargetPixels(cam, target_depth, cam, source_depth, 0.01), 0);
  EXPECT_EQ(CountVisibleTargetPixels(cam, target_depth, cam, source_depth, 0.10, 2), 50);
  SourceSelectionOptions bad;
  bad.k = 0;
  EXPECT_THROW(bad.Check(), Error);
}

TEST(SourceSelectionTest, ThreadCountDoesNotChangeTheResult) {
  const Scene scene = MakeTestScene(5, 48, 36);
  const PinholeCamera target = scene.ToSceneCamera(ArcCamera(0.05, 48, 36));
  const Image depth = scene.RenderDepth(target);
  SourceSelectionOptions one, many;
  one.num_threads = 1;
  many.num_threads = 4;
  const auto a = SelectSources(scene, target, depth, one);
  const auto b = SelectSources(scene, target, depth, many);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].view_index, b[i].view_index);
    EXPECT_EQ(a[i].count, b[i].count);
  }
}

}  // namespace
}  // namespace fvs
