// The network as a rendering method, with small random-weight models made here: finite,
// deterministic output of the target's size, source features encoded once across targets,
// and clear errors for missing or mismatched weights. (Image quality needs trained
// weights: that is the training issue's and the evaluation's business.)
#include "fvs/render/fvs_method.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "fvs/net/net.h"
#include "fvs/render/method.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"
#include "render/render_fixture.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

// Random weights of `variant` (from `seed`) saved as <dir>/<file_stem>.safetensors
// (default: the variant's name).
std::string SaveRandomModel(const std::string& dir, const std::string& variant,
                            int seed = 7, const std::string& file_stem = "") {
  torch::manual_seed(seed);
  const ModelConfig config = ModelConfig::ForVariant(variant);
  FvsNet net(config);
  const std::string path =
      dir + "/" + (file_stem.empty() ? variant : file_stem) + ".safetensors";
  SaveWeights(net, config, path, /*fp16=*/false);
  return path;
}

using testing::HeldOutTarget;

TEST(FvsMethod, FiniteDeterministicAndCached) {
  testing::TempDir dir;
  const Scene scene = testing::MakeTestScene(5, 48, 36);
  RenderOptions options;
  options.num_sources = 3;
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast");
  std::unique_ptr<Method> method = CreateMethod("fvs", options);
  EXPECT_EQ(method->name(), "fvs_fast");

  const TargetView target = HeldOutTarget(scene, 2);
  const RenderResult a = method->Render(scene, target);
  ASSERT_EQ(a.color.width, 48);
  ASSERT_EQ(a.color.height, 36);
  ASSERT_EQ(a.color.channels, 3);
  EXPECT_TRUE(testing::AllFinite(a.color));
  EXPECT_TRUE(testing::AllFinite(a.confidence));
  for (float v : a.color.data) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
  }
  EXPECT_EQ(a.sources.size(), 3u);
  for (const SourceScore& s : a.sources) EXPECT_NE(s.view_index, 2);
  EXPECT_GT(a.timings.encode_s, 0.0);

  // Same target again: identical image, and no source encoded a second time.
  const RenderResult b = method->Render(scene, target);
  EXPECT_EQ(a.color.data, b.color.data);
  EXPECT_EQ(b.timings.encode_s, 0.0);

  // No cache at all (every source dropped while the frame still uses it): the same image,
  // every source encoded again.
  options.feature_cache_mb = 0;
  std::unique_ptr<Method> uncached = CreateMethod("fvs", options);
  for (int round = 0; round < 2; ++round) {
    const RenderResult c = uncached->Render(scene, target);
    EXPECT_EQ(a.color.data, c.color.data);
    EXPECT_GT(c.timings.encode_s, 0.0);
  }
}

std::vector<std::string> FilesBelow(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// --disk_feature_cache: a second run reads the features the first one encoded (the very
// same image), a damaged file is encoded again, other weights never read them.
TEST(FvsMethod, FeaturesKeptOnDiskAreReadByTheNextRun) {
  testing::TempDir dir;
  const Scene scene = testing::MakeTestScene(5, 48, 36);
  RenderOptions options;
  options.num_sources = 3;
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast");
  options.feature_cache_dir = dir / "features";
  const std::string stored_model = options.model_path;
  const TargetView target = HeldOutTarget(scene, 2);
  const RenderResult fresh = CreateMethod("fvs", options)->Render(scene, target);
  const std::vector<std::string> stored = FilesBelow(options.feature_cache_dir);
  ASSERT_EQ(stored.size(), 3u);  // one per source used, nothing else (no temporaries)

  // A new run (empty memory cache): the same image from the stored features.
  EXPECT_EQ(CreateMethod("fvs", options)->Render(scene, target).color.data,
            fresh.color.data);

  // Proof that they are read: features zeroed on disk change the image.
  for (const std::string& path : stored) {
    SafeTensorsFile file = ReadSafeTensors(path);
    SafeTensor zeros = file.tensors.at(0);
    std::fill(zeros.data.begin(), zeros.data.end(), 0);
    file.Add(zeros);
    WriteSafeTensors(path, file);
  }
  EXPECT_NE(CreateMethod("fvs", options)->Render(scene, target).color.data,
            fresh.color.data);

  // Truncated files: a warning, the sources encoded again, the files rewritten whole.
  for (const std::string& path : stored) {
    std::filesystem::resize_file(path, 100);
  }
  EXPECT_EQ(CreateMethod("fvs", options)->Render(scene, target).color.data,
            fresh.color.data);
  for (const std::string& path : stored) EXPECT_NO_THROW(ReadSafeTensors(path));
  EXPECT_EQ(FilesBelow(options.feature_cache_dir), stored);

  // Other weights (same variant, other values): their own folder, stored features unused.
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast", /*seed=*/8, "other");
  CreateMethod("fvs", options)->Render(scene, target);
  EXPECT_EQ(FilesBelow(options.feature_cache_dir).size(), 6u);

  // Over the size limit (0 here) the least recently used files go, never the one just
  // written: one file left, the render unchanged.
  options.model_path = stored_model;
  options.feature_cache_dir = dir / "small";
  options.feature_cache_disk_mb = 0;
  EXPECT_EQ(CreateMethod("fvs", options)->Render(scene, target).color.data,
            fresh.color.data);
  EXPECT_EQ(FilesBelow(options.feature_cache_dir).size(), 1u);

  // A folder that cannot be created (a file in the way): a warning, the same render.
  testing::WriteTextFile(dir / "a_file", "not a folder");
  options.feature_cache_dir = dir / "a_file/features";
  EXPECT_EQ(CreateMethod("fvs", options)->Render(scene, target).color.data,
            fresh.color.data);
}

TEST(FvsMethod, EveryVariantRendersFiniteImages) {
  testing::TempDir dir;
  const Scene scene = testing::MakeTestScene(4, 40, 32);
  for (const char* variant :
       {"fvs", "fvs_nogru", "fvs_nomasks", "fvs_noinfdepth", "fvs_single"}) {
    RenderOptions options;
    options.num_sources = 2;
    options.model_path = SaveRandomModel(dir.path(), variant);
    const RenderResult r =
        CreateMethod(variant, options)->Render(scene, HeldOutTarget(scene, 1));
    EXPECT_TRUE(testing::AllFinite(r.color)) << variant;
    EXPECT_EQ(r.color.width, 40) << variant;
  }
}

// fvs_fast starts from the ULR blend (ModelConfig::ulr_prior, rgb_skip, zero heads): the
// untrained network must render what the `ulr` method renders, black where no source sees
// the pixel included, and the background seen at infinity (the sky scene) too. What
// remains is float rounding and the prior's floor (kUlrWeightFloor).
TEST(FvsMethod, UntrainedFastNetworkRendersTheUlrBlend) {
  testing::TempDir dir;
  const Scene room = testing::MakeTestScene(6, 64, 48);
  const Scene sky = testing::MakeTestSkyScene(6, 64, 48);
  RenderOptions options;
  options.num_sources = 4;
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast");
  // The network samples its inputs bilinearly (grid_sample); `ulr` samples bicubically
  // by default.
  options.interpolation = "bilinear";
  for (const auto& [scene_ptr, view] :
       {std::make_pair(&room, 1), std::make_pair(&room, 3), std::make_pair(&sky, 2)}) {
    SCOPED_TRACE(view);
    const Scene& scene = *scene_ptr;
    const TargetView target = HeldOutTarget(scene, view);
    const RenderResult net = CreateMethod("fvs", options)->Render(scene, target);
    const RenderResult ulr = CreateMethod("ulr", options)->Render(scene, target);
    ASSERT_EQ(net.color.data.size(), ulr.color.data.size());
    double sum = 0, worst = 0;
    int covered = 0, close = 0;
    for (size_t i = 0; i < ulr.coverage.data.size(); ++i) {
      // Every pixel: where no source sees it both render black.
      covered += ulr.coverage.data[i] > 0;
      double diff = 0;
      for (int c = 0; c < 3; ++c) {
        diff = std::max<double>(
            diff, std::abs(net.color.data[3 * i + c] - ulr.color.data[3 * i + c]));
      }
      sum += diff;
      worst = std::max(worst, diff);
      close += diff < 1.0 / 255;
    }
    ASSERT_GT(covered, 1000);
    EXPECT_EQ(net.infinity.data, ulr.infinity.data);
    if (scene_ptr == &sky) {
      int at_infinity = 0;
      for (float v : ulr.infinity.data) at_infinity += v > 0;
      EXPECT_GT(at_infinity, 500);
    }
    const double pixels = static_cast<double>(ulr.coverage.data.size());
    EXPECT_LT(sum / pixels, 1e-3) << "worst " << worst;
    EXPECT_GT(close / pixels, 0.99) << "worst " << worst;
  }
}

float MaxDifference(const Image& a, const Image& b) {
  EXPECT_EQ(a.data.size(), b.data.size());
  float worst = 0;
  for (size_t i = 0; i < a.data.size() && i < b.data.size(); ++i) {
    worst = std::max(worst, std::abs(a.data[i] - b.data[i]));
  }
  return worst;
}

// Tiles put each block of the blend where it belongs: with a context box as large as the
// image every tile sees exactly what the whole target sees (a network with random,
// context-dependent heads), and with no context at all a network whose output depends on
// each pixel alone (untrained fvs_fast: the ULR blend) renders the same image too.
TEST(FvsMethod, TiledBlendEqualsTheWholeTarget) {
  testing::TempDir dir;
  const Scene scene = testing::MakeTestScene(5, 32, 24);
  const TargetView target = HeldOutTarget(scene, 2);
  // fvs_nogru: context-dependent like fvs, at less than half its cost.
  for (const char* variant : {"fvs_nogru", "fvs_fast"}) {
    SCOPED_TRACE(variant);
    const bool fvs = std::string(variant) == "fvs_nogru";
    RenderOptions options;
    options.num_sources = 3;
    options.model_path = SaveRandomModel(dir.path(), variant);
    options.tile_size = 0;
    const RenderResult whole = CreateMethod("fvs", options)->Render(scene, target);
    options.tile_size = fvs ? 16 : 11;  // 2 x 2 tiles; 3 x 3 tiles
    options.tile_overlap = fvs ? 32 : 0;
    std::unique_ptr<Method> tiled_method = CreateMethod("fvs", options);
    const RenderResult tiled = tiled_method->Render(scene, target);
    EXPECT_LT(MaxDifference(whole.color, tiled.color), 1e-5f);
    EXPECT_LT(MaxDifference(whole.confidence, tiled.confidence), 1e-5f);
    EXPECT_EQ(whole.coverage.data, tiled.coverage.data);
    if (fvs) {
      // A small context does change a context-dependent blend, but nothing non-finite
      // comes out of the seams.
      options.tile_overlap = 2;
      const RenderResult seams = CreateMethod("fvs", options)->Render(scene, target);
      EXPECT_TRUE(testing::AllFinite(seams.color));
      EXPECT_GT(MaxDifference(whole.color, seams.color), 0.0f);
    }
  }
  // fvs_agg (random heads: context-dependent) in 3 x 3 tiles of a larger target with its
  // own overlap: the tiles see all the context the whole target does.
  const Scene large = testing::MakeTestScene(5, 96, 72);
  const TargetView large_target = HeldOutTarget(large, 2);
  RenderOptions options;
  options.num_sources = 3;
  {
    // Its heads start at zero (the ULR blend, pixel by pixel): give them weights.
    torch::manual_seed(3);
    const ModelConfig config = ModelConfig::ForVariant("fvs_agg");
    FvsNet net(config);
    torch::NoGradGuard no_grad;
    for (auto& p : net->parameters()) p.add_(torch::randn_like(p) * 0.05);
    options.model_path = dir.path() + "/fvs_agg_random.safetensors";
    SaveWeights(net, config, options.model_path, /*fp16=*/false);
  }
  options.tile_size = 0;
  const RenderResult whole = CreateMethod("fvs", options)->Render(large, large_target);
  options.tile_size = 32;
  options.tile_overlap = -1;  // the network's own
  const RenderResult tiled = CreateMethod("fvs", options)->Render(large, large_target);
  EXPECT_LT(MaxDifference(whole.color, tiled.color), 1e-5f);
  RenderOptions bad;
  bad.tile_size = 3;
  EXPECT_THROW(bad.Check(), Error);
}

// bf16 runs on the CPU (oneDNN) with warping and blend weights kept in fp32: the image
// stays within a few 8-bit levels of fp32. fp16 needs CUDA, and so does --device cuda.
TEST(FvsMethod, Bf16IsCloseToFp32AndFp16NeedsCuda) {
  testing::TempDir dir;
  const Scene scene = testing::MakeTestScene(5, 40, 30);
  const TargetView target = HeldOutTarget(scene, 2);
  for (const char* variant : {"fvs_fast", "fvs_nogru"}) {
    SCOPED_TRACE(variant);
    RenderOptions options;
    options.num_sources = 3;
    options.device = "cpu";
    options.model_path = SaveRandomModel(dir.path(), variant);
    const RenderResult fp32 = CreateMethod("fvs", options)->Render(scene, target);
    options.precision = "bf16";
    const RenderResult bf16 = CreateMethod("fvs", options)->Render(scene, target);
    EXPECT_TRUE(testing::AllFinite(bf16.color));
    EXPECT_TRUE(testing::AllFinite(bf16.confidence));
    double sum = 0;
    for (size_t i = 0; i < fp32.color.data.size(); ++i) {
      sum += std::abs(fp32.color.data[i] - bf16.color.data[i]);
    }
    EXPECT_LT(sum / fp32.color.data.size(), 4.0 / 255);
    EXPECT_LT(MaxDifference(fp32.color, bf16.color), 0.1f);
    EXPECT_EQ(fp32.coverage.data, bf16.coverage.data);
  }
  RenderOptions options;
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast");
  options.device = "cpu";
  options.precision = "fp16";
  EXPECT_THROW(CreateMethod("fvs", options), Error);
  if (!torch::cuda::is_available()) {
    options.precision = "fp32";
    options.device = "cuda";
    EXPECT_THROW(CreateMethod("fvs", options), Error);
  }
  options.precision = "fp8";
  EXPECT_THROW(options.Check(), Error);
}

TEST(FvsMethod, NoSourceSeesTheTargetGivesBlack) {
  testing::TempDir dir;
  const Scene scene = testing::MakeTestScene(3, 40, 32);
  RenderOptions options;
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast");
  TargetView target = HeldOutTarget(scene, 0);
  // Far above the closed room, looking horizontally away from it: nothing in view.
  target.camera = testing::LookAtCamera(Eigen::Vector3d(0, 0, 50),
                                        Eigen::Vector3d(100, 0, 50), 40, 32);
  const RenderResult r = CreateMethod("fvs", options)->Render(scene, target);
  EXPECT_TRUE(r.sources.empty());
  for (float v : r.color.data) EXPECT_EQ(v, 0.0f);
}

TEST(FvsMethod, MissingOrMismatchedWeightsAreOneLineErrors) {
  testing::TempDir dir;
  RenderOptions options;
  EXPECT_THROW(CreateMethod("fvs", options), Error);
  options.model_path = dir / "missing.safetensors";
  EXPECT_THROW(CreateMethod("fvs", options), Error);
  options.model_path = SaveRandomModel(dir.path(), "fvs_fast");
  try {
    CreateMethod("fvs_nogru", options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("variant 'fvs_fast'"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace fvs
