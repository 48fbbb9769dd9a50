// The packed training set and the trainer's data path: pack -> read back, leave-one-out
// source selection, the sampler, and the trainer's warp, which is the renderer's
// (geometry/warp.h) fed from tensors.
#include "fvs/train/pack.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>

#include "fvs/geometry/warp.h"
#include "fvs/net/net.h"
#include "fvs/scene/source_selection.h"
#include "fvs/train/data.h"
#include "fvs/train/train_options.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::TempDir;

torch::Tensor CameraK(const PinholeCamera& c) {
  return torch::tensor({c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0}, torch::kDouble)
      .reshape({3, 3});
}
torch::Tensor CameraR(const PinholeCamera& c) {
  std::vector<double> v;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) v.push_back(c.R(r, k));
  return torch::tensor(v, torch::kDouble).reshape({3, 3});
}
torch::Tensor CameraT(const PinholeCamera& c) {
  return torch::tensor({c.t.x(), c.t.y(), c.t.z()}, torch::kDouble);
}
torch::Tensor DepthTensor(const Image& d) {
  return torch::from_blob(const_cast<float*>(d.data.data()), {d.height, d.width},
                          torch::kFloat)
      .clone();
}

class PackTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    scene_ = new Scene(testing::MakeTestScene(6, 96, 72));
    PackOptions options;
    options.scale = 0.5;
    summary_ = PackScene(*scene_, options, dir_->path() + "/packed");
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete dir_;
  }
  static TempDir* dir_;
  static Scene* scene_;
  static PackSummary summary_;
};
TempDir* PackTest::dir_ = nullptr;
Scene* PackTest::scene_ = nullptr;
PackSummary PackTest::summary_;

TEST(ResizeAreaTest, AveragesExactFootprints) {
  Image image(8, 4, 1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) image.at(x, y) = static_cast<float>(x + 10 * y);
  const Image half = ResizeArea(image, 4, 2);
  // Output (0,0) averages x 0..1, y 0..1: (0 + 1 + 10 + 11) / 4.
  EXPECT_NEAR(half.at(0, 0), 5.5f, 1e-5);
  // Output (3,1) averages x 6..7, y 2..3.
  EXPECT_NEAR(half.at(3, 1), (26 + 27 + 36 + 37) / 4.0f, 1e-5);
  // Non-integer factor: the mean is preserved.
  const Image odd = ResizeArea(image, 3, 3);
  double a = 0, b = 0;
  for (float v : image.data) a += v;
  for (float v : odd.data) b += v;
  EXPECT_NEAR(a / image.data.size(), b / odd.data.size(), 1e-4);
}

TEST_F(PackTest, ReadsBackWhatWasPacked) {
  EXPECT_EQ(summary_.num_views, 6);
  EXPECT_EQ(summary_.width, 48);
  EXPECT_EQ(summary_.height, 36);
  const PackedScene p = LoadPackedScene(dir_->path() + "/packed");
  ASSERT_EQ(p.num_views(), 6);
  EXPECT_EQ(p.width(), 48);
  EXPECT_EQ(p.height(), 36);
  EXPECT_EQ(p.names[2], scene_->view(2).name);
  for (int i = 0; i < 6; ++i) {
    const PinholeCamera c = scene_->view(i).camera.Resized(48, 36);
    EXPECT_TRUE(torch::equal(p.K[i], CameraK(c)));
    EXPECT_TRUE(torch::equal(p.R[i], CameraR(c)));
    EXPECT_TRUE(torch::equal(p.t[i], CameraT(c)));
    EXPECT_TRUE(torch::allclose(p.depths[i], DepthTensor(scene_->RenderDepth(c))));
    const Image small = ResizeArea(scene_->SourceImage(i), 48, 36);
    const torch::Tensor expected = torch::from_blob(const_cast<float*>(small.data.data()),
                                                    {36, 48, 3}, torch::kFloat)
                                       .permute({2, 0, 1});
    const torch::Tensor got = p.images[i].to(torch::kFloat) / 255.0;
    EXPECT_LE((got - expected).abs().max().item<float>(), 0.5f / 255 + 1e-6);
  }
  // The overlap matrix: 0 diagonal, fractions, neighbours on the arc overlap most.
  EXPECT_EQ(p.overlap.diagonal().abs().sum().item<float>(), 0.f);
  EXPECT_TRUE((p.overlap >= 0).all().item<bool>() && (p.overlap <= 1).all().item<bool>());
  for (int i = 0; i < 5; ++i) {
    EXPECT_GT(p.overlap[i][i + 1].item<float>(), 0.3f) << i;
    if (i + 3 < 6) {
      EXPECT_GT(p.overlap[i][i + 1].item<float>(), p.overlap[i][i + 3].item<float>());
    }
  }
  // Overlap agrees with the CPU source ranking on the same data.
  const PinholeCamera c0 = scene_->view(0).camera.Resized(48, 36);
  const PinholeCamera c1 = scene_->view(1).camera.Resized(48, 36);
  const Image d0 = scene_->RenderDepth(c0), d1 = scene_->RenderDepth(c1);
  int64_t surface = 0;
  for (float d : d0.data) surface += d > 0;
  EXPECT_NEAR(p.overlap[0][1].item<float>(),
              double(CountVisibleTargetPixels(c0, d0, c1, d1, 0.1)) / surface, 1e-6);
}

TEST_F(PackTest, SourcesExcludeTheTargetAndFollowOverlap) {
  const PackedScene p = LoadPackedScene(dir_->path() + "/packed");
  for (int target = 0; target < 6; ++target) {
    for (int k : {1, 3, 5, 9}) {
      const std::vector<int> s = SelectTrainingSources(p, target, k);
      EXPECT_LE(static_cast<int>(s.size()), k);
      EXPECT_EQ(std::count(s.begin(), s.end(), target), 0);
      for (size_t i = 0; i < s.size(); ++i) {
        EXPECT_GT(p.overlap[target][s[i]].item<float>(), 0.f);
        if (i > 0) {
          EXPECT_GE(p.overlap[target][s[i - 1]].item<float>(),
                    p.overlap[target][s[i]].item<float>());
        }
      }
      // Every view left out has no more overlap than the last one taken.
      std::set<int> taken(s.begin(), s.end());
      for (int j = 0; j < 6; ++j) {
        if (j == target || taken.count(j) || s.empty()) continue;
        EXPECT_LE(p.overlap[target][j].item<float>(),
                  p.overlap[target][s.back()].item<float>());
      }
    }
  }
}

TEST_F(PackTest, SamplerIsLeaveOneOutAndReproducible) {
  std::vector<PackedScene> scenes = {LoadPackedScene(dir_->path() + "/packed")};
  SamplerOptions options;
  options.num_sources = 3;
  options.crop = 24;
  TrainingSampler a(&scenes, options, 7), b(&scenes, options, 7);
  std::set<int> targets;
  for (int i = 0; i < 40; ++i) {
    const TrainingSample s = a.Next();
    targets.insert(s.target);
    EXPECT_EQ(std::count(s.sources.begin(), s.sources.end(), s.target), 0);
    EXPECT_EQ(s.sources, SelectTrainingSources(scenes[0], s.target, 3));
    EXPECT_EQ(s.target_rgb.sizes(), torch::IntArrayRef({1, 3, 24, 24}));
    EXPECT_EQ(s.source_rgb.sizes(),
              torch::IntArrayRef({static_cast<int64_t>(s.sources.size()), 3, 36, 48}));
    EXPECT_EQ(s.warp.grid.sizes(),
              torch::IntArrayRef({static_cast<int64_t>(s.sources.size()), 24, 24, 2}));
    EXPECT_TRUE(s.x0 >= 0 && s.x0 + 24 <= 48 && s.y0 >= 0 && s.y0 + 24 <= 36);
    EXPECT_TRUE(torch::isfinite(s.warp.grid).all().item<bool>());
    EXPECT_GE(s.target_rgb.min().item<float>(), 0.f);
    EXPECT_LE(s.target_rgb.max().item<float>(), 1.f);
    const TrainingSample t = b.Next();
    EXPECT_EQ(t.target, s.target);
    EXPECT_EQ(t.x0, s.x0);
    EXPECT_TRUE(torch::equal(t.target_rgb, s.target_rgb));
  }
  EXPECT_GE(targets.size(), 4u);
  // The state carries the stream: a sampler restored from it draws the same next sample.
  const std::string state = a.State();
  const TrainingSample next = a.Next();
  TrainingSampler c(&scenes, options, 99);
  c.SetState(state);
  const TrainingSample again = c.Next();
  EXPECT_EQ(again.target, next.target);
  EXPECT_EQ(again.x0, next.x0);
  EXPECT_EQ(again.y0, next.y0);
  EXPECT_TRUE(torch::equal(again.source_rgb, next.source_rgb));
  EXPECT_THROW(c.SetState("not a state"), Error);
}

TEST_F(PackTest, HoldoutTargetsAreTheHeldOutViewsAndNeverSources) {
  std::vector<PackedScene> scenes = {LoadPackedScene(dir_->path() + "/packed")};
  PackedScene& p = scenes[0];
  // No view held out: every view is a target either way.
  for (int v = 0; v < 6; ++v) {
    EXPECT_TRUE(IsTargetView(p, v, false));
    EXPECT_TRUE(IsTargetView(p, v, true));
  }
  p.holdout[1] = p.holdout[4] = true;
  EXPECT_EQ(ValidationTargets(p, 10, true), (std::vector<int>{1, 4}));
  EXPECT_EQ(ValidationTargets(p, 10, false), (std::vector<int>{0, 2, 3, 5}));
  SamplerOptions options;
  options.num_sources = 3;
  options.crop = 24;
  options.holdout_targets = true;
  TrainingSampler sampler(&scenes, options, 3);
  std::set<int> targets;
  for (int i = 0; i < 30; ++i) {
    const TrainingSample s = sampler.Next();
    targets.insert(s.target);
    for (int j : s.sources) EXPECT_FALSE(p.holdout[j]);
  }
  EXPECT_EQ(targets, (std::set<int>{1, 4}));
  options.holdout_targets = false;
  TrainingSampler in_geometry(&scenes, options, 3);
  for (int i = 0; i < 30; ++i) EXPECT_FALSE(p.holdout[in_geometry.Next().target]);
}

TEST_F(PackTest, CroppedSourcesSampleExactlyWhatTheFullSourcesDo) {
  std::vector<PackedScene> scenes = {LoadPackedScene(dir_->path() + "/packed")};
  SamplerOptions full_options;
  full_options.num_sources = 3;
  full_options.crop = 16;
  full_options.augment = false;
  SamplerOptions crop_options = full_options;
  crop_options.source_margin = 2;
  TrainingSampler full(&scenes, full_options, 5), cropped(&scenes, crop_options, 5);
  int smaller = 0;
  for (int i = 0; i < 30; ++i) {
    const TrainingSample a = full.Next(), b = cropped.Next();
    ASSERT_EQ(a.target, b.target);
    ASSERT_EQ(a.x0, b.x0);
    EXPECT_EQ(b.source_rgb.size(2) % 4 == 0 || b.source_rgb.size(2) == 36, true);
    EXPECT_LE(b.source_rgb.size(2) * b.source_rgb.size(3),
              a.source_rgb.size(2) * a.source_rgb.size(3));
    smaller += b.source_rgb.size(2) * b.source_rgb.size(3) <
               a.source_rgb.size(2) * a.source_rgb.size(3);
    EXPECT_TRUE(torch::equal(a.warp.valid_warp, b.warp.valid_warp));
    const torch::Tensor sa = WarpFeatures(a.source_rgb, a.warp.grid);
    const torch::Tensor sb = WarpFeatures(b.source_rgb, b.warp.grid);
    EXPECT_LT((sa - sb).abs().max().item<float>(), 1e-5f) << "sample " << i;
  }
  EXPECT_GT(smaller, 0);
  // Nothing near any source: left as it is.
  TrainingSample nothing = full.Next();
  nothing.warp.grid.fill_(std::numeric_limits<float>::quiet_NaN());
  const auto size = nothing.source_rgb.sizes().vec();
  CropSourcesToFootprint(&nothing, 2, 4);
  EXPECT_EQ(nothing.source_rgb.sizes().vec(), size);
}

TEST_F(PackTest, ColourJitterIsTheSameForTargetAndSources) {
  std::vector<PackedScene> scenes = {LoadPackedScene(dir_->path() + "/packed")};
  // The target crop and a source that is the same image must stay identical.
  TrainingSample s = MakeSample(scenes[0], 1, {1}, 0, 0, 48, 36, SampleWarpOptions());
  ColorJitter j;
  j.brightness = 0.05;
  j.contrast = 1.1;
  j.saturation = 0.8;
  j.gain[0] = 1.05;
  const torch::Tensor before = s.target_rgb.clone();
  ApplyColorJitter(j, &s);
  EXPECT_GT((s.target_rgb - before).abs().max().item<float>(), 0.01f);
  EXPECT_LE(((s.source_rgb + 1) * 0.5 - s.target_rgb).abs().max().item<float>(), 1e-5f);
}

// The trainer's warp is the renderer's: on random target cameras (perturbed arc cameras)
// its grid and masks are exactly ComputeWarpMap's of the same cameras and depths (the
// tensors reach the one warp unchanged), and its ULR prior is the renderer's weights.
TEST_F(PackTest, TrainingWarpIsTheRenderersWarp) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  int64_t compared = 0, valid = 0, valid_at_infinity = 0, mask_mismatch = 0;
  double max_grid_error = 0, max_prior_error = 0;
  for (int trial = 0; trial < 6; ++trial) {
    // Scene cameras are scene-centred.
    PinholeCamera target = scene_->ToSceneCamera(testing::ArcCamera(jitter(rng), 40, 30));
    target.fx *= 1 + 0.2 * jitter(rng);
    target.cy += 3 * jitter(rng);
    target.t += Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)) * 0.5;
    // The top rows without a surface in the target and in the sources: a background
    // beyond the mesh, warped at infinity.
    Image target_depth = scene_->RenderDepth(target);
    std::fill(target_depth.data.begin(), target_depth.data.begin() + 8 * 40, 0.f);
    std::vector<PinholeCamera> sources;
    std::vector<Image> source_depths;
    for (int k : {0, 2, 5}) {
      sources.push_back(scene_->view(k).camera.Resized(48, 36));
      source_depths.push_back(scene_->RenderDepth(sources.back()));
      std::fill(source_depths.back().data.begin(),
                source_depths.back().data.begin() + 10 * 48, 0.f);
    }
    std::vector<torch::Tensor> ks, rs, ts, ds;
    for (size_t k = 0; k < sources.size(); ++k) {
      ks.push_back(CameraK(sources[k]));
      rs.push_back(CameraR(sources[k]));
      ts.push_back(CameraT(sources[k]));
      ds.push_back(DepthTensor(source_depths[k]));
    }
    SampleWarpOptions settings;
    settings.ulr_log_weights = true;
    const TrainingWarp warp = ComputeTrainingWarp(
        CameraK(target), CameraR(target), CameraT(target), DepthTensor(target_depth),
        torch::stack(ks), torch::stack(rs), torch::stack(ts), torch::stack(ds), settings);
    // The ULR prior against the renderer's per-point weights (net/ulr_weights.h) from
    // the CPU warp's masks and the cameras in double.
    UlrSources ulr;
    ulr.target_focal = std::sqrt(target.fx * target.fy);
    for (const PinholeCamera& src : sources) {
      ulr.centers.push_back(target.WorldToCamera(src.Center()));
      ulr.focals.push_back(std::sqrt(src.fx * src.fy));
    }
    std::vector<WarpMap> maps;
    for (size_t k = 0; k < sources.size(); ++k) {
      maps.push_back(ComputeWarpMap(target, target_depth, sources[k], source_depths[k]));
    }
    const torch::Tensor prior = warp.ulr_log_weights.contiguous();
    ASSERT_EQ(prior.sizes().vec(), std::vector<int64_t>({3, 1, 30, 40}));
    for (int i = 0; i < 30 * 40; ++i) {
      bool sees[3];
      double weights[3];
      for (int k = 0; k < 3; ++k) sees[k] = maps[k].valid_warp.data[i] > 0;
      const float d = target_depth.data[i];
      const Eigen::Vector3d point =
          d > 0 ? target.PixelToCamera(i % 40 + 0.5, i / 40 + 0.5, d)
                : UlrPointAtInfinity(target.PixelToCamera(i % 40 + 0.5, i / 40 + 0.5, 1),
                                     UlrFarDistance(ulr));
      UlrPointWeights(point, ulr, sees, UlrOptions(), weights);
      for (int k = 0; k < 3; ++k) {
        const double expected = std::log(std::max(weights[k], kUlrWeightFloor));
        max_prior_error = std::max(
            max_prior_error, std::abs(prior.data_ptr<float>()[k * 1200 + i] - expected));
      }
    }
    for (size_t k = 0; k < sources.size(); ++k) {
      const WarpMap map =
          ComputeWarpMap(target, target_depth, sources[k], source_depths[k]);
      const Image grid = GridSampleCoordinates(map, 48, 36);
      const auto g = warp.grid[k].contiguous();
      const auto vw = warp.valid_warp[k][0].contiguous();
      const auto vd = warp.valid_depth[0][0].contiguous();
      for (int y = 0; y < 30; ++y) {
        for (int x = 0; x < 40; ++x) {
          const size_t i = static_cast<size_t>(y) * 40 + x;
          EXPECT_EQ(vd.data_ptr<float>()[i], map.valid_depth.data[i]);
          mask_mismatch += vw.data_ptr<float>()[i] != map.valid_warp.data[i];
          valid += map.valid_warp.data[i] > 0;
          valid_at_infinity += map.valid_warp.data[i] > 0 && map.valid_depth.data[i] == 0;
          max_grid_error = std::max<double>(
              max_grid_error,
              std::max(std::abs(g.data_ptr<float>()[2 * i] - grid.data[2 * i]),
                       std::abs(g.data_ptr<float>()[2 * i + 1] - grid.data[2 * i + 1])));
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(valid, compared / 4);  // the test sees real warps, not an empty mask
  EXPECT_GT(valid_at_infinity, compared / 20);  // and the background at infinity
  EXPECT_EQ(mask_mismatch, 0);
  EXPECT_EQ(max_grid_error, 0.0);
  EXPECT_LT(max_prior_error, 1e-4);
}

TEST_F(PackTest, NoInfDepthLeavesSkyInvalid) {
  std::vector<PackedScene> scenes = {LoadPackedScene(dir_->path() + "/packed")};
  // A crop with no surface at all: zero the target depth.
  PackedScene p = scenes[0];
  p.depths = p.depths.clone();
  p.depths[0].zero_();
  SampleWarpOptions settings;
  settings.geometry.at_infinity = false;
  const TrainingSample s = MakeSample(p, 0, {1, 2}, 0, 0, 48, 36, settings);
  EXPECT_EQ(s.warp.valid_depth.sum().item<float>(), 0.f);
  EXPECT_EQ(s.warp.valid_warp.sum().item<float>(), 0.f);
  EXPECT_TRUE(torch::isfinite(s.warp.grid).all().item<bool>());
  settings.geometry.at_infinity = true;
  // Points at infinity: their source positions are finite (valid only where the source
  // has sky too, which this closed room has nowhere).
  const TrainingSample t = MakeSample(p, 0, {1, 2}, 0, 0, 48, 36, settings);
  EXPECT_TRUE(torch::isfinite(t.warp.grid).all().item<bool>());
  EXPECT_EQ(t.warp.valid_warp.sum().item<float>(), 0.f);
}

// The command's path: a COLMAP dense workspace on disk (photos, sparse model, mesh)
// loaded with Scene::Load, then packed.
TEST(PackWorkspaceTest, PacksAPreparedWorkspace) {
  TempDir dir;
  const std::string ws = dir / "ws";
  const auto views = testing::ArcViews(4, 64, 48);
  testing::WriteTestWorkspace(ws, views, testing::MakeTestWorldMesh());
  const Scene scene = Scene::Load(ws);
  PackOptions options;
  options.scale = 0.5;
  const PackSummary summary = PackScene(scene, options, dir / "packed");
  EXPECT_EQ(summary.num_views, 4);
  EXPECT_GT(summary.mean_overlap, 0.1);
  const PackedScene p = LoadPackedScene(dir / "packed");
  ASSERT_EQ(p.num_views(), 4);
  EXPECT_EQ(p.width(), 32);
  EXPECT_EQ(p.height(), 24);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(p.names[i], scene.view(i).name);
    EXPECT_GT((p.depths[i] > 0).sum().item<int64_t>(), 24 * 32 / 2);
  }
  EXPECT_EQ(ReadSafeTensors(summary.path).metadata.at("workspace"), ws);
  // Fewer than 2 views cannot be a training scene; a scale that leaves nothing is
  // refused.
  options.scale = 0.1;
  EXPECT_THROW(PackScene(scene, options, dir / "tiny"), Error);
}

TEST_F(PackTest, BadFilesAndListsGiveClearErrors) {
  const std::string packed = dir_->path() + "/packed";
  // A truncated scene file.
  const std::string bad = dir_->path() + "/bad";
  std::filesystem::create_directories(bad);
  {
    const std::string bytes = ReadFileToString(packed + "/scene.safetensors");
    std::ofstream out(bad + "/scene.safetensors", std::ios::binary);
    out.write(bytes.data(), bytes.size() / 2);
  }
  EXPECT_THROW(LoadPackedScene(bad), Error);
  EXPECT_THROW(LoadPackedScene(dir_->path() + "/nothing"), Error);

  const std::string list = dir_->path() + "/list.txt";
  testing::WriteTextFile(list, "# scenes\npacked\n\nmissing_scene\n");
  try {
    ReadSceneList(list);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("list.txt:4"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos)
        << e.what();
  }
  std::filesystem::create_directories(dir_->path() + "/unpacked");
  testing::WriteTextFile(list, "packed\nunpacked\n");
  try {
    ReadSceneList(list);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("list.txt:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("view_synthesis_pack"), std::string::npos);
  }
  testing::WriteTextFile(list, "packed\n");
  EXPECT_EQ(ReadSceneList(list).size(), 1u);
  testing::WriteTextFile(list, "\n# nothing\n");
  EXPECT_THROW(ReadSceneList(list), Error);
}

}  // namespace
}  // namespace fvs
