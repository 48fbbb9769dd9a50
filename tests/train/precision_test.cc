// Mixed precision in the trainer and the trainer-only render benchmark: the autocast
// scope turns on and restores LibTorch's state, a bf16 step (--Train.precision bf16) is
// finite, keeps fp32 weights and changes them, the option parses and bad values are
// refused, and the benchmark renders its grid into render_benchmark.csv.
#include "fvs/net/precision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fvs/net/lpips_weights.h"
#include "fvs/train/pack.h"
#include "fvs/train/packed_render.h"
#include "fvs/train/trainer.h"
#include "fvs/util/error.h"
#include "scene/scene_fixture.h"
#include "support/test_support.h"
#include "train/tiny_net.h"

namespace fvs {
namespace {

using testing::TempDir;

using testing::kTinyNet;
using testing::kTinyNetNoSkip;

class PrecisionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ::unsetenv(kLpipsPathEnv);
    dir_ = new TempDir();
    PackOptions options;
    options.scale = 1.0;
    PackScene(testing::MakeTestScene(6, 64, 48), options, dir_->path() + "/scene_a");
    testing::WriteTextFile(dir_->path() + "/train.txt", "scene_a\n");
  }
  static void TearDownTestSuite() { delete dir_; }

  static TrainOptions Options(const std::string& output) {
    TrainOptions o =
        testing::TinyTrainOptions(dir_->path() + "/train.txt", dir_->path() + "/" + output);
    o.max_steps = 2;
    return o;
  }
  static TempDir* dir_;
};
TempDir* PrecisionTest::dir_ = nullptr;

TEST_F(PrecisionTest, AutocastGuardTurnsOnAndRestores) {
  ASSERT_FALSE(AutocastEnabled(torch::kCPU));
  const torch::Tensor x = torch::rand({1, 3, 8, 8});
  const torch::Tensor w = torch::rand({4, 3, 3, 3});
  {
    AutocastGuard off(torch::kCPU, torch::kFloat32);  // fp32: a no-op scope
    EXPECT_FALSE(off.active());
    EXPECT_FALSE(AutocastEnabled(torch::kCPU));
  }
  {
    AutocastGuard on(torch::kCPU, torch::kBFloat16);
    EXPECT_TRUE(on.active());
    EXPECT_TRUE(AutocastEnabled(torch::kCPU));
    EXPECT_EQ(torch::conv2d(x, w).scalar_type(), torch::kBFloat16);
    {
      AutocastGuard nested(torch::kCPU, torch::kBFloat16);
      EXPECT_TRUE(AutocastEnabled(torch::kCPU));
    }
    EXPECT_TRUE(AutocastEnabled(torch::kCPU));  // the outer scope's state is back
  }
  EXPECT_FALSE(AutocastEnabled(torch::kCPU));
  EXPECT_EQ(torch::conv2d(x, w).scalar_type(), torch::kFloat32);
  // fp16 autocast is CUDA's only.
  EXPECT_THROW(AutocastGuard(torch::kCPU, torch::kHalf), Error);
  EXPECT_EQ(PrecisionDtype("bf16"), torch::kBFloat16);
  EXPECT_THROW(PrecisionDtype("int8"), Error);
}

TEST_F(PrecisionTest, Bf16StepIsFiniteAndChangesTheFp32Weights) {
  // Without the colour skip every layer gets a gradient at the first step (with it only
  // the zero-initialised heads do).
  TrainOptions o = Options("bf16");
  o.model_config_json = kTinyNetNoSkip;
  o.precision = "bf16";
  Trainer trainer(o);
  std::vector<torch::Tensor> before;
  for (const auto& p : trainer.net()->parameters()) before.push_back(p.detach().clone());
  const LossValue loss = trainer.Step();
  EXPECT_TRUE(std::isfinite(loss.l1) && std::isfinite(loss.second));
  EXPECT_GT(loss.l1, 0);
  EXPECT_FALSE(AutocastEnabled(torch::kCPU));  // the step's scope ended
  int changed = 0, i = 0;
  for (const auto& p : trainer.net()->parameters()) {
    EXPECT_EQ(p.scalar_type(), torch::kFloat32);
    EXPECT_TRUE(torch::isfinite(p).all().item<bool>());
    if (!torch::equal(p, before[i++])) ++changed;
  }
  EXPECT_GT(changed, static_cast<int>(before.size()) / 2);

  // The same first step in fp32 and bf16 (same seed, same sample): close, not equal, so
  // the autocast scope reached the network's convolutions.
  double l1[2];
  for (int i = 0; i < 2; ++i) {
    TrainOptions same = Options(i ? "noskip_bf16" : "noskip_fp32");
    same.model_config_json = kTinyNetNoSkip;
    same.precision = i ? "bf16" : "fp32";
    Trainer t(same);
    l1[i] = t.Step().l1;
  }
  EXPECT_NE(l1[0], l1[1]);
  EXPECT_NEAR(l1[0], l1[1], 0.05 * l1[0]);
}

TEST_F(PrecisionTest, OptionParsesAndBadValuesAreRefused) {
  auto parse = [](std::vector<std::string> extra, TrainOptions* parsed) {
    *parsed = TrainOptions();
    std::vector<std::string> args = {"prog", "--scene_list", "L", "--output_path", "M"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    return ParseTrainOptions(static_cast<int>(argv.size()), argv.data(), 1, parsed);
  };
  TrainOptions parsed;
  EXPECT_EQ(parsed.precision, "fp32");
  EXPECT_TRUE(parse({"--Train.precision", "bf16"}, &parsed));
  EXPECT_EQ(parsed.precision, "bf16");
  EXPECT_THROW(parse({"--Train.precision", "fp16"}, &parsed), Error);
  EXPECT_THROW(parse({"--Train.precision", "BF16"}, &parsed), Error);
  // The benchmark's grid.
  EXPECT_TRUE(parse({"--val_scene_list", "V", "--Train.benchmark", "1",
                     "--Train.bench_sizes", "64x48, 32x24", "--Train.bench_ks", "2,1"},
                    &parsed));
  const BenchmarkGrid grid = ParseBenchmarkGrid(parsed);
  ASSERT_EQ(grid.sizes.size(), 2u);
  EXPECT_EQ(grid.sizes[1], std::make_pair(32, 24));
  EXPECT_EQ(grid.ks, std::vector<int>({2, 1}));
  EXPECT_EQ(grid.precisions.size(), 3u);
  EXPECT_THROW(parse({"--val_scene_list", "V", "--Train.benchmark", "1",
                      "--Train.bench_sizes", "64by48"},
                     &parsed),
               Error);
  EXPECT_THROW(parse({"--val_scene_list", "V", "--Train.benchmark", "1",
                      "--Train.bench_precisions", "fp32,int8"},
                     &parsed),
               Error);
  EXPECT_THROW(parse({"--Train.benchmark", "1"}, &parsed), Error);  // no val list
}

TEST_F(PrecisionTest, RenderBenchmarkWritesItsGrid) {
  TrainOptions o = Options("bench");
  o.val_scene_list = dir_->path() + "/train.txt";
  o.benchmark = true;
  o.bench_sizes = "64x48,96x72";
  o.bench_ks = "1,2";
  o.bench_precisions = "fp32,bf16,fp16";  // fp16 skipped on the CPU
  RunTraining(o);
  std::ifstream in(o.output_path + "/render_benchmark.csv");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("width,height,k,precision,views,warp_s", 0), 0u) << line;
  int rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::stringstream s(line);
    std::vector<std::string> f;
    for (std::string x; std::getline(s, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 12u) << line;
    EXPECT_NE(f[3], "fp16");
    const double psnr = std::stod(f[10]), ulr = std::stod(f[11]);
    EXPECT_TRUE(std::isfinite(psnr) && psnr > 5) << line;
    EXPECT_TRUE(std::isfinite(ulr) && ulr > 5) << line;
  }
  EXPECT_EQ(rows, 2 * 2 * 2);
  // The resize scales the intrinsics with the images.
  const PackedScene scene = LoadPackedScene(dir_->path() + "/scene_a");
  const PackedScene big = ResizePackedScene(scene, 128, 72);
  EXPECT_EQ(big.width(), 128);
  EXPECT_EQ(big.height(), 72);
  EXPECT_NEAR(big.K[0][0][0].item<double>(), scene.K[0][0][0].item<double>() * 2, 1e-9);
  EXPECT_NEAR(big.K[0][1][2].item<double>(), scene.K[0][1][2].item<double>() * 1.5, 1e-9);
}

}  // namespace
}  // namespace fvs
