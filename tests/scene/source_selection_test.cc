// Source selection on the in-memory test world: ranking by overlap, exclusion, depth
// tolerance, sources that see nothing, K larger than the scene, threads not changing
// results, the background at infinity, the adaptive K.
#include "fvs/scene/source_selection.h"

#include <gtest/gtest.h>

#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "geometry/geometry_test_util.h"

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
  PinholeCamera cam = testing::CenteredCamera(20, 10, 20);
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

// A target of sky alone (no surface anywhere) still gets the sources that see its sky:
// those looking the same way, with no surface there themselves, best overlap first; a
// source looking away, or with a surface in front of the sky, sees none of it.
TEST(SourceSelectionTest, RanksSourcesByWhatTheySeeAtInfinityWhenThereIsNoSurface) {
  const Eigen::Vector3d eye(0, 0, 0);
  const PinholeCamera target =
      testing::LookAtCamera(eye, Eigen::Vector3d(0, 10, 0), 40, 30);
  const PinholeCamera same = testing::LookAtCamera(eye + Eigen::Vector3d(1, 0, 0),
                                                   Eigen::Vector3d(1, 10, 0), 40, 30);
  const PinholeCamera turned =
      testing::LookAtCamera(eye, Eigen::Vector3d(4, 10, 0), 40, 30);  // ~22 degrees
  const PinholeCamera away =
      testing::LookAtCamera(eye, Eigen::Vector3d(0, -10, 0), 40, 30);
  const Image no_surface(40, 30, 1, 0.f);
  const Image wall(40, 30, 1, 2.f);  // a surface in front of everything
  const std::vector<PinholeCamera> sources = {away, turned, same, same};
  const std::vector<const Image*> depths = {&no_surface, &no_surface, &no_surface, &wall};
  SourceSelectionOptions options;
  options.k = 5;
  const auto chosen = SelectSources(target, no_surface, sources, depths, options);
  ASSERT_EQ(chosen.size(), 2u);
  EXPECT_EQ(chosen[0].view_index, 2);  // the same direction: every pixel
  EXPECT_EQ(chosen[0].infinity_count, 40 * 30);
  EXPECT_EQ(chosen[0].count, 0);
  EXPECT_EQ(chosen[1].view_index, 1);
  EXPECT_GT(chosen[1].infinity_count, 0);
  EXPECT_LT(chosen[1].infinity_count, 40 * 30);
}

// The adaptive K: at least min_k, at most k, in ranking order, and every source beyond
// min_k adds at least min_gain of the target's pixels that fewer than wanted_views
// sources saw; with no gain asked for, every source that adds anything; with an
// impossible gain, exactly min_k.
TEST(SourceSelectionTest, AdaptiveKTakesSourcesWhileTheyAddCoverage) {
  const Scene scene = MakeTestScene(12, 48, 36);
  const PinholeCamera target = scene.ToSceneCamera(ArcCamera(0.05, 48, 36));
  const Image depth = scene.RenderDepth(target);
  SourceSelectionOptions options;
  options.adaptive = true;
  options.k = 8;
  options.min_k = 2;
  options.wanted_views = 2;
  options.min_gain = 0.02;
  const SourceRanking ranking = RankSources(scene, target, depth, options);
  ASSERT_GT(ranking.ranked.size(), 8u);
  EXPECT_EQ(ranking.num_pixels, 48 * 36);
  const auto chosen = ChooseSources(ranking, ranking.ranked, options);
  ASSERT_GE(chosen.size(), 2u);
  ASSERT_LE(chosen.size(), 8u);
  EXPECT_EQ(chosen[0].view_index, ranking.ranked[0].view_index);
  EXPECT_EQ(chosen[1].view_index, ranking.ranked[1].view_index);
  // Replay the rule: each later source's gain over the ones before it.
  std::vector<int> views(ranking.num_pixels, 0);
  const auto seen = [&](int view, int64_t i) {
    return (ranking.seen[view][i >> 6] >> (i & 63)) & 1;
  };
  size_t next = 0;  // into chosen
  for (const SourceScore& s : ranking.ranked) {
    if (next == chosen.size()) break;
    int64_t gain = 0;
    for (int64_t i = 0; i < ranking.num_pixels; ++i) {
      gain += seen(s.view_index, i) && views[i] < options.wanted_views;
    }
    const bool taken = chosen[next].view_index == s.view_index;
    if (next >= 2) {
      EXPECT_EQ(taken, gain >= options.min_gain * ranking.num_pixels && gain > 0)
          << "view " << s.view_index << " gain " << gain;
    }
    if (!taken) continue;
    for (int64_t i = 0; i < ranking.num_pixels; ++i) views[i] += seen(s.view_index, i);
    ++next;
  }
  EXPECT_EQ(next, chosen.size());

  options.min_gain = 1.0;
  EXPECT_EQ(ChooseSources(ranking, ranking.ranked, options).size(), 2u);
  options.min_gain = 0;
  options.wanted_views = 255;
  EXPECT_EQ(ChooseSources(ranking, ranking.ranked, options).size(), 8u);
  // Fixed K is the top K of the same ranking.
  options.adaptive = false;
  options.k = 3;
  const auto top = ChooseSources(ranking, ranking.ranked, options);
  ASSERT_EQ(top.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(top[i].view_index, ranking.ranked[i].view_index);
  SourceSelectionOptions bad;
  bad.min_gain = 1.5;
  EXPECT_THROW(bad.Check(), Error);
}

}  // namespace
}  // namespace fvs
