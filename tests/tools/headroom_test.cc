// The headroom tool (tools/headroom/): the oracles and the photo-free blends on a tiny
// packed scene, the fitted per-pixel choice, the depth sweep and the depth stereo. A
// measurement instrument, not the product: doc/training.md has what it measured.
#include "tools/headroom/headroom.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fvs/net/net.h"
#include "fvs/train/data.h"
#include "fvs/train/pack.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"
#include "tools/headroom/choice_evidence.h"
#include "tools/headroom/consensus.h"
#include "tools/headroom/depth_stereo.h"
#include "tools/headroom/depth_sweep.h"

namespace fvs {
namespace {

using testing::TempDir;

// The depth refinements' case: view 2 of `scene` with its own proxy scaled by `factor`
// (only the target's: an occlusion tolerance that still lets its sources see it; in a
// real workspace the target's and the sources' depths come from one mesh), its top-3
// sources, its `ulr` blend and the pixels a refinement may move.
struct DepthCase {
  PackedScene scene;
  SampleWarpOptions warp;
  TrainingSample sample;
  torch::Tensor ulr, refinable;
};

DepthCase MakeDepthCase(const PackedScene& scene, float factor) {
  DepthCase c;
  c.scene = scene;
  c.scene.depths = scene.depths.clone();
  c.scene.depths[2].mul_(factor);
  c.warp.ulr_log_weights = true;
  c.warp.geometry.occlusion_tolerance = 0.05;
  c.sample = MakeSample(c.scene, 2, SelectTrainingSources(scene, 2, 3), 0, 0,
                        scene.width(), scene.height(), c.warp);
  const TrainingSample& s = c.sample;
  const torch::Tensor colours = (WarpFeatures(s.source_rgb, s.warp.grid) + 1) * 0.5;
  c.ulr = BlendSeen(colours, s.warp.valid_warp, s.warp.ulr_log_weights);
  c.refinable = Refinable(s);
  return c;
}

double PsnrOf(const torch::Tensor& a, const torch::Tensor& b) {
  return -10 * std::log10((a - b).pow(2).mean().item<double>());
}

// scene_a: six views of the test world, packed at full size.
class HeadroomTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    PackOptions options;
    options.scale = 1.0;
    PackScene(testing::MakeTestScene(6, 64, 48), options, dir_->path() + "/scene_a");
  }
  static void TearDownTestSuite() { delete dir_; }
  static TempDir* dir_;
};
TempDir* HeadroomTest::dir_ = nullptr;

// The headroom rows: every method for the scene and for all, finite, the oracles that
// see the photo no worse than `ulr` on this scene, and the per-pixel oracle no worse than
// the per-block one (it may choose per pixel what the block oracle chooses per block).
// The photo-free blends (consensus, alignment, exposure matching): finite, and the
// consensus ones not above the per-pixel oracle.
TEST_F(HeadroomTest, HeadroomReportsUlrTheOraclesAndThePhotoFreeBlends) {
  const PackedScene scene = LoadPackedScene(dir_->path() + "/scene_a");
  const auto rows = MeasureHeadroom({scene}, 2, 2, SampleWarpOptions{}, nullptr);
  std::map<std::string, double> psnr;
  for (const HeadroomRow& r : rows) {
    EXPECT_EQ(r.views, 2) << r.scene << " " << r.method;
    EXPECT_TRUE(std::isfinite(r.psnr) && std::isfinite(r.ssim)) << r.method;
    EXPECT_EQ(r.lpips, -1);
    if (r.scene == "all") psnr[r.method] = r.psnr;
  }
  ASSERT_EQ(rows.size(), 2 * psnr.size());
  ASSERT_GT(psnr.size(), 5u);
  EXPECT_EQ(psnr.count("oracle_colour"), 1u);
  EXPECT_EQ(psnr.count("exposure_affine"), 1u);
  EXPECT_GE(psnr["oracle_pixel"], psnr["ulr"] - 1e-6);
  EXPECT_GE(psnr["oracle_pixel"], psnr["oracle_patch8"] - 1e-6);
  EXPECT_GE(psnr["oracle_global"], psnr["ulr"] - 0.05);
  int consensus = 0;
  for (const auto& [method, value] : psnr) {
    if (method.rfind("consensus_", 0) != 0) continue;
    ++consensus;
    EXPECT_LE(value, psnr["oracle_pixel"] + 1e-6) << method;
  }
  EXPECT_GT(consensus, 0);
  EXPECT_EQ(psnr.count("stereo_3pc_s4_r3_p0.3_0.2_1_a0.5"), 1u);

  // --Train.headroom_methods: only the rows asked for, the same figures; none is an
  // error.
  const auto some = MeasureHeadroom({scene}, 2, 2, SampleWarpOptions{}, nullptr, false,
                                    {}, "ulr,stereo");
  std::set<std::string> methods;
  for (const HeadroomRow& r : some) {
    methods.insert(r.method);
    if (r.scene == "all") EXPECT_NEAR(r.psnr, psnr[r.method], 1e-9) << r.method;
  }
  EXPECT_EQ(methods.size(), 3u);
  EXPECT_EQ(methods.count("ulr"), 1u);
  EXPECT_THROW(
      MeasureHeadroom({scene}, 2, 2, SampleWarpOptions{}, nullptr, false, {}, "nosuch"),
      Error);
}

// The choice evidence (train/choice_evidence.h) of a scene whose proxy is its true
// surface: finite, bounded, zero for sources that do not see a pixel, the occlusion
// residual small where a source sees the point; an unfitted model blends exactly as the
// ULR weights do, and fitting lowers its L1 on the pixels it fits.
TEST_F(HeadroomTest, ChoiceEvidenceIsBoundedAndAFittedChoiceLowersItsError) {
  torch::set_num_threads(1);
  const PackedScene scene = LoadPackedScene(dir_->path() + "/scene_a");
  SampleWarpOptions warp;
  warp.ulr_log_weights = true;
  const TrainingSample s = MakeSample(scene, 2, SelectTrainingSources(scene, 2, 3), 0, 0,
                                      scene.width(), scene.height(), warp);
  const torch::Tensor colours = (WarpFeatures(s.source_rgb, s.warp.grid) + 1) * 0.5;
  const torch::Tensor e = SourceEvidence(scene, s, colours);
  const torch::Tensor& seen = s.warp.valid_warp;
  ASSERT_EQ(e.sizes(), (std::vector<int64_t>{3, kNumEvidence, 48, 64}));
  EXPECT_TRUE(torch::isfinite(e).all().item<bool>());
  EXPECT_LE(e.abs().max().item<double>(), 4.0);
  EXPECT_EQ((e * (1 - seen)).abs().max().item<double>(), 0.0);
  ASSERT_GT(seen.sum().item<double>(), 100);
  const torch::Tensor occlusion = e.select(1, kEvidenceOcclusionAbs).unsqueeze(1);
  EXPECT_LT(((occlusion * seen).sum() / seen.sum()).item<double>(), 0.1);
  EXPECT_GT(e.select(1, kEvidenceBorder).max().item<double>(), 0.5);

  ChoiceModel unfitted(16);
  const torch::Tensor ulr = BlendSeen(colours, seen, s.warp.ulr_log_weights);
  const torch::Tensor blend =
      BlendSeen(colours, seen, unfitted->forward(e, s.warp.ulr_log_weights));
  EXPECT_LT((blend - ulr).abs().max().item<double>(), 1e-6);

  ChoiceFitOptions options;
  options.hidden = 4;
  options.steps = 60;
  options.pixels_per_view = 512;
  const ChoiceFit fit = FitChoiceModel({scene}, 2, warp, false, options, true);
  EXPECT_EQ(fit.pixels, 512 * scene.num_views());
  EXPECT_TRUE(std::isfinite(fit.final_error));
  EXPECT_LT(fit.final_error, fit.start_error);
  // Rows for the fitted model in the headroom tool.
  const auto rows =
      MeasureHeadroom({scene}, 2, 2, warp, nullptr, false, {{"choice_mlp4", fit.model}});
  int found = 0;
  for (const HeadroomRow& r : rows) {
    if (r.method != "choice_mlp4") continue;
    ++found;
    EXPECT_TRUE(std::isfinite(r.psnr) && std::isfinite(r.ssim));
  }
  EXPECT_EQ(found, 2);

  // The squared-error fit of the local channels only leaves the per-view channels out.
  options.squared_error = true;
  options.local_only = true;
  const ChoiceFit local = FitChoiceModel({scene}, 2, warp, false, options, true);
  EXPECT_LT(local.final_error, local.start_error);
  torch::Tensor changed = e.clone();
  changed.narrow(1, kEvidenceCoverage, kNumEvidence - kEvidenceCoverage).fill_(3.0);
  const torch::NoGradGuard no_grad;
  // How far a model's log-weights move when the per-view channels change.
  const auto moved_by_per_view_channels = [&](ChoiceModel model) {
    return (model->forward(changed, s.warp.ulr_log_weights) -
            model->forward(e, s.warp.ulr_log_weights))
        .abs()
        .max()
        .item<double>();
  };
  EXPECT_EQ(moved_by_per_view_channels(local.model), 0.0);
  EXPECT_GT(moved_by_per_view_channels(fit.model), 0.0);
}

TEST(ChoiceSpecs, ParseAndNameOrRefuseInOneLine) {
  const std::vector<ChoiceFitOptions> fits = ParseChoiceSpecs("0:l1:all,16:l2:local");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(ChoiceSpecName(fits[0]), "choice_h0_l1_all");
  EXPECT_EQ(ChoiceSpecName(fits[1]), "choice_h16_l2_local");
  EXPECT_TRUE(ParseChoiceSpecs("").empty());
  std::set<std::string> names;  // one name a channel (the list follows the enum)
  for (int c = 0; c < kNumEvidence; ++c) {
    ASSERT_NE(EvidenceChannelName(c), nullptr) << c;
    names.insert(EvidenceChannelName(c));
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kNumEvidence));
  EXPECT_EQ(names.count("?"), 0u);
  EXPECT_STREQ(EvidenceChannelName(kEvidenceGlobalBlendDistance),
               "global_blend_distance");
  for (const char* bad : {"16", "16:l3:all", "x:l1:all", "16:l1:some", "16:l1:all:4",
                          "-1:l1:all", "99999:l1:all"}) {
    EXPECT_THROW(ParseChoiceSpecs(bad), Error) << bad;
  }
}

// The depth sweep (train/depth_sweep.h) on a scene whose proxy is its true surface keeps
// the proxy's depth where the sources agree; with the target's proxy 3 % too far it
// moves the pixels back (the chosen change near -3 %) and renders closer to the photo
// than `ulr` over the wrong proxy (part of the way: the 3x3 window on this smooth
// texture picks noisy depths).
TEST_F(HeadroomTest, DepthSweepFindsTheDepthWhereTheSourcesAgree) {
  torch::set_num_threads(1);
  const PackedScene scene = LoadPackedScene(dir_->path() + "/scene_a");
  DepthSweepOptions options;
  options.radius = 1;
  torch::Tensor chosen;
  const DepthCase exact = MakeDepthCase(scene, 1.0f);
  const torch::Tensor kept =
      DepthSweepBlend(exact.scene, exact.sample, exact.warp, options, &chosen);
  EXPECT_TRUE(torch::isfinite(kept).all().item<bool>());
  EXPECT_GE(PsnrOf(kept, exact.sample.target_rgb),
            PsnrOf(exact.ulr, exact.sample.target_rgb) - 0.5);

  const DepthCase off = MakeDepthCase(scene, 1.03f);
  const torch::Tensor swept =
      DepthSweepBlend(off.scene, off.sample, off.warp, options, &chosen);
  ASSERT_GT(off.refinable.sum().item<int64_t>(), 200);
  EXPECT_NEAR(chosen.masked_select(off.refinable).median().item<double>(), -0.03, 0.011);
  // Measured: 32.96 against 32.74 dB (34.45 with the true proxy).
  EXPECT_GT(PsnrOf(swept, off.sample.target_rgb),
            PsnrOf(off.ulr, off.sample.target_rgb) + 0.1);

  options.steps = 0;
  EXPECT_THROW(DepthSweepBlend(off.scene, off.sample, off.warp, options), Error);
}

// Semi-global matching (train/depth_stereo.h): without penalties it is the cost summed
// over its four paths (the same choice per pixel); with them a lone pixel whose cost
// prefers another candidate than all its neighbours follows them, while a whole region
// that prefers it keeps it.
TEST(DepthStereoTest, SemiGlobalMatchingSmoothsLoneChoicesAndKeepsRegions) {
  torch::Tensor cost = torch::rand({5, 9, 11}) * 0.1;
  cost.select(0, 2).sub_(0.5);       // candidate 2 everywhere
  cost.index_put_({4, 4, 5}, -1.0);  // one pixel prefers candidate 4
  cost.index_put_({0, torch::indexing::Slice(0, 4), torch::indexing::Slice(0, 4)},
                  -1.0);  // a 4x4 region candidate 0
  const torch::Tensor plain = SemiGlobalAggregate(cost, 0, 0);
  EXPECT_TRUE(plain.allclose(cost * 4, 1e-5, 1e-5));
  const torch::Tensor choice = SemiGlobalAggregate(cost, 0.05, 0.8).argmin(0);
  EXPECT_EQ(choice[4][5].item<int64_t>(), 2);
  EXPECT_EQ(choice[1][1].item<int64_t>(), 0);
  EXPECT_EQ(choice[7][8].item<int64_t>(), 2);
  cost.index_put_({1, 1, 1}, std::numeric_limits<float>::quiet_NaN());
  EXPECT_THROW(SemiGlobalAggregate(cost, 0.05, 0.6), Error);
  EXPECT_THROW(SemiGlobalAggregate(torch::zeros({3, 4}), 0.05, 0.6), Error);
}

// The stereo refinement on the scene of the depth sweep's test: with the target's proxy
// 3 % too far it moves the pixels back and renders closer to the photo than `ulr` over
// the wrong proxy; bad options are refused.
TEST_F(HeadroomTest, DepthStereoFindsTheDepthWhereTheSourcesCorrelate) {
  torch::set_num_threads(1);
  const DepthCase off = MakeDepthCase(LoadPackedScene(dir_->path() + "/scene_a"), 1.03f);
  DepthStereoOptions options;
  options.radius = 2;
  // This smooth texture correlates almost as well at every depth: no pull toward the
  // proxy (with prior 0.02 the median stays at 0).
  options.prior = 0;
  options.absolute_weight = 0.5;
  torch::Tensor chosen;
  const torch::Tensor refined =
      DepthStereoBlend(off.scene, off.sample, off.warp, options, &chosen);
  EXPECT_TRUE(torch::isfinite(refined).all().item<bool>());
  ASSERT_GT(off.refinable.sum().item<int64_t>(), 200);
  EXPECT_NEAR(chosen.masked_select(off.refinable).median().item<double>(), -0.03, 0.008);
  // Measured: 32.97 against 32.74 dB.
  EXPECT_GT(PsnrOf(refined, off.sample.target_rgb),
            PsnrOf(off.ulr, off.sample.target_rgb) + 0.1);
  options.p2 = options.p1 / 2;
  EXPECT_THROW(DepthStereoBlend(off.scene, off.sample, off.warp, options), Error);
}

// Colour consensus (tools/headroom/consensus.h): sources that agree keep their weights,
// one that disagrees over its window loses it, and the term stays finite and at most 0
// for any colours, tau or window. The window means: equal inside the image; at a corner
// BoxMean counts the replicated border, BoxMeanInImage only the pixels inside.
// SeenWeights masks before the softmax: a hidden source with a huge log-weight does not
// take the seeing sources' weight (masking after a softmax over all left them e^-40 each,
// and their blend black); where nothing sees, all weights and the blend are 0.
TEST(ConsensusTest, SeenWeightsAreASoftmaxOverTheSeeingSourcesOnly) {
  const torch::Tensor log_weights =
      torch::tensor({40.f, 0.f, std::log(3.f)}).view({3, 1, 1, 1});
  const torch::Tensor seen = torch::tensor({0.f, 1.f, 1.f}).view({3, 1, 1, 1});
  const torch::Tensor w = SeenWeights(log_weights, seen).flatten();
  EXPECT_NEAR(w[0].item<float>(), 0, 1e-7);
  EXPECT_NEAR(w[1].item<float>(), 0.25, 1e-6);
  EXPECT_NEAR(w[2].item<float>(), 0.75, 1e-6);
  const torch::Tensor colours = torch::tensor({9.f, 1.f, 2.f}).view({3, 1, 1, 1});
  EXPECT_NEAR(BlendSeen(colours, seen, log_weights).item<float>(), 1.75, 1e-6);
  EXPECT_EQ(BlendSeen(colours, torch::zeros_like(seen), log_weights).item<float>(), 0);
  EXPECT_EQ(SeenWeights(log_weights, torch::zeros_like(seen)).abs().sum().item<float>(),
            0);
}

TEST(ConsensusTest, BoxMeansAgreeInsideAndDifferAtTheBorderAsDocumented) {
  const torch::Tensor x = torch::arange(36, torch::kFloat).reshape({1, 1, 6, 6});
  const torch::Tensor replicated = BoxMean(x, 1), inside = BoxMeanInImage(x, 1);
  EXPECT_TRUE(torch::allclose(replicated.narrow(2, 1, 4).narrow(3, 1, 4),
                              inside.narrow(2, 1, 4).narrow(3, 1, 4)));
  EXPECT_NEAR(inside[0][0][0][0].item<double>(), (0 + 1 + 6 + 7) / 4.0, 1e-5);
  EXPECT_NEAR(replicated[0][0][0][0].item<double>(), (4 * 0 + 2 * 1 + 2 * 6 + 7) / 9.0,
              1e-5);
  EXPECT_TRUE(torch::equal(BoxMeanInImage(x, 0), x));
}

TEST(ConsensusTest, ADisagreeingSourceLosesItsWeightAndAgreeingOnesKeepTheirs) {
  torch::manual_seed(3);
  const torch::Tensor base = torch::rand({1, 3, 12, 14});
  torch::Tensor colours = base.repeat({4, 1, 1, 1});
  const torch::Tensor seen = torch::ones({4, 1, 12, 14});
  const torch::Tensor log_weights = torch::zeros({4, 1, 12, 14});
  ConsensusOptions options{0.05, 2, 1};
  EXPECT_LT(
      ConsensusLogWeights(colours, seen, log_weights, options).abs().max().item<float>(),
      1e-6);
  colours[3] = 1 - colours[3];
  const torch::Tensor term = ConsensusLogWeights(colours, seen, log_weights, options);
  EXPECT_LT(term[3].mean().item<float>(), -5.0);
  EXPECT_GT(term.narrow(0, 0, 3).mean().item<float>(), term[3].mean().item<float>() + 4);
  options.tau = 0;
  EXPECT_EQ(
      ConsensusLogWeights(colours, seen, log_weights, options).abs().max().item<float>(),
      0);
  for (const double tau : {1e-6, 0.05, 1e6}) {
    options = {tau, 4, 3};
    const torch::Tensor t = ConsensusLogWeights(
        colours * 1e6, seen * (torch::rand_like(seen) > 0.5), log_weights, options);
    EXPECT_TRUE(torch::isfinite(t).all().item<bool>()) << tau;
    EXPECT_LE(t.max().item<float>(), 0) << tau;
  }
}

// A source the proxy put one pixel off lands back on the others after alignment.
TEST(ConsensusTest, AlignmentMovesAShiftedSourceBackOntoTheOthers) {
  torch::manual_seed(4);
  const torch::Tensor base = torch::rand({1, 3, 16, 18});
  torch::Tensor colours = base.repeat({3, 1, 1, 1});
  colours[2] = torch::roll(base[0], {1}, {2});  // one pixel to the right
  torch::Tensor seen = torch::ones({3, 1, 16, 18});
  const torch::Tensor log_weights = torch::log(torch::tensor({0.45f, 0.45f, 0.1f}))
                                        .view({3, 1, 1, 1})
                                        .expand({3, 1, 16, 18});
  AlignToBlend(&colours, &seen, log_weights, {2, 2, 1e-4, 1});
  const torch::Tensor interior = (colours[2] - base[0]).narrow(1, 3, 10).narrow(2, 3, 12);
  EXPECT_LT(interior.abs().max().item<float>(), 1e-6);
  EXPECT_TRUE(torch::isfinite(colours).all().item<bool>());
}

}  // namespace
}  // namespace fvs
