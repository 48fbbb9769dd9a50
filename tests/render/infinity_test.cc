// The background beyond the proxy mesh (issue 17): a scene whose far "sky" is in the
// photos but not in the mesh (MakeTestSkyScene). Its pixels have no target depth; the
// renderers warp them from the sources at infinity (geometry/warp.h) and must give the
// background back, where push-pull hole filling (the old fate of those pixels) smears
// the floor and the box over it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "fvs/render/method.h"
#include "fvs/util/hole_filling.h"
#include "render/render_fixture.h"
#include "scene/scene_fixture.h"

namespace fvs {
namespace {

// Mean absolute error over the colour channels of the pixels where mask > 0.
double MeanAbsError(const Image& a, const Image& b, const Image& mask) {
  double sum = 0;
  int64_t n = 0;
  for (size_t i = 0; i < mask.data.size(); ++i) {
    if (mask.data[i] <= 0) continue;
    for (int c = 0; c < 3; ++c) sum += std::abs(a.data[3 * i + c] - b.data[3 * i + c]);
    n += 3;
  }
  return n > 0 ? sum / n : 0.0;
}

int64_t Count(const Image& mask) {
  int64_t n = 0;
  for (float v : mask.data) n += v > 0;
  return n;
}

class InfinityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(testing::MakeTestSkyScene(8, 96, 72));
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }
  // View `view` held out and rendered by `method` from the others, holes left black.
  static RenderResult RenderUnfilled(const std::string& method, int view) {
    RenderOptions raw;
    raw.fill_holes = false;
    return CreateMethod(method, raw)
        ->Render(*scene_, testing::HeldOutTarget(*scene_, view));
  }
  static Scene* scene_;
};

Scene* InfinityTest::scene_ = nullptr;

// Stated bound: mean absolute error < 0.03 (of [0,1]) over the background pixels the
// sources see at infinity, with push-pull at least 3 times worse on the same pixels.
// Measured on views 2, 3 and 5: see the printout.
TEST_F(InfinityTest, UlrGivesTheBackgroundBackWherePushPullDoesNot) {
  for (int view : {2, 3, 5}) {
    SCOPED_TRACE(view);
    const Image& truth = scene_->SourceImage(view);
    const RenderResult ulr = RenderUnfilled("ulr", view);
    ASSERT_EQ(ulr.infinity.width, 96);
    int64_t background = 0;
    for (float d : ulr.depth.data) background += !(d > 0);
    const int64_t at_infinity = Count(ulr.infinity);
    // Most of the background is seen by some source; the sky takes a third or more of
    // the view.
    EXPECT_GT(background, 96 * 72 / 4);
    EXPECT_GT(at_infinity, 0.9 * background);
    const double ulr_error = MeanAbsError(ulr.color, truth, ulr.infinity);

    // What those pixels got before: holes, filled by push-pull from around them.
    Image coverage = ulr.coverage;
    for (size_t i = 0; i < coverage.data.size(); ++i) {
      if (ulr.infinity.data[i] > 0) coverage.data[i] = 0.f;
    }
    Image pushed = ulr.color;
    FillHoles(coverage, &ulr.depth, &pushed);
    const double push_pull_error = MeanAbsError(pushed, truth, ulr.infinity);
    std::printf(
        "view %d: %lld background pixels, %lld at infinity; mean |error| there: "
        "ulr %.4f, push-pull %.4f\n",
        view, static_cast<long long>(background), static_cast<long long>(at_infinity),
        ulr_error, push_pull_error);
    EXPECT_LT(ulr_error, 0.03);
    EXPECT_GT(push_pull_error, 3 * ulr_error);
    EXPECT_GT(push_pull_error, 0.05);
  }
}

// `nearest` takes the background from its one source where that source sees it at
// infinity, as it takes surfaces.
TEST_F(InfinityTest, NearestTakesTheBackgroundFromItsSource) {
  const RenderResult nearest = RenderUnfilled("nearest", 3);
  EXPECT_GT(Count(nearest.infinity), 96 * 72 / 5);
  const double error =
      MeanAbsError(nearest.color, scene_->SourceImage(3), nearest.infinity);
  std::printf("nearest: %lld pixels at infinity, mean |error| %.4f\n",
              static_cast<long long>(Count(nearest.infinity)), error);
  EXPECT_LT(error, 0.03);
}

// Hole filling changes only the pixels that no source sees, not even at infinity; the
// mask marks exactly the covered pixels without a surface.
TEST_F(InfinityTest, FillingLeavesPixelsSeenAtInfinityAlone) {
  const RenderResult black = RenderUnfilled("ulr", 2);
  const RenderResult filled = CreateMethod("ulr", RenderOptions{})
                                  ->Render(*scene_, testing::HeldOutTarget(*scene_, 2));
  ASSERT_EQ(filled.infinity.data, black.infinity.data);
  for (size_t i = 0; i < filled.coverage.data.size(); ++i) {
    const bool surface = filled.depth.data[i] > 0;
    const bool covered = filled.coverage.data[i] > 0;
    EXPECT_EQ(filled.infinity.data[i], !surface && covered ? 1.f : 0.f);
    if (covered) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(filled.color.data[3 * i + c], black.color.data[3 * i + c]);
      }
    }
  }
  EXPECT_TRUE(testing::AllFinite(filled.color));
}

}  // namespace
}  // namespace fvs
