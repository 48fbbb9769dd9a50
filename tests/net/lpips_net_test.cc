// The LPIPS network as a module: where its weights are found (--lpips_path over
// FVS_LPIPS_PATH), the smallest images its layers take, and that it measures batches,
// pads images smaller than that, and passes finite gradients to its input.
#include "fvs/net/lpips_net.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "fvs/util/error.h"
#include "net/lpips_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

TEST(LpipsNet, FlagWinsOverTheEnvironment) {
  testing::ScopedEnv unset(kLpipsPathEnv, nullptr);
  EXPECT_EQ(ResolveLpipsPath(""), "");
  EXPECT_EQ(ResolveLpipsPath("flag.safetensors"), "flag.safetensors");
  testing::ScopedEnv set(kLpipsPathEnv, "/env/lpips_alex.safetensors");
  EXPECT_EQ(ResolveLpipsPath(""), "/env/lpips_alex.safetensors");
  EXPECT_EQ(ResolveLpipsPath("flag.safetensors"), "flag.safetensors");
}

TEST(LpipsNet, MinimumSizesFollowTheLayers) {
  // AlexNet: conv1 11x11 stride 4, then two 3x3 stride-2 pools before relu3..5.
  EXPECT_EQ(LpipsMinimumSize("alex"), 31);
  // VGG16: four 2x2 pools before relu5_3.
  EXPECT_EQ(LpipsMinimumSize("vgg"), 16);
  EXPECT_THROW(LpipsMinimumSize("squeeze"), Error);
}

TEST(LpipsNet, MeasuresBatchesAndSmallImagesWithFiniteGradients) {
  testing::TempDir dir;
  torch::manual_seed(3);
  LpipsNet lpips(testing::WriteRandomLpips(dir / "alex.safetensors", "alex"));
  EXPECT_EQ(lpips->network(), "alex");
  EXPECT_TRUE(lpips->parameters().empty()) << "frozen: nothing for an optimiser";
  for (const int side : {128, 20}) {  // 20 < 31: padded
    const torch::Tensor target = torch::rand({2, 3, side, side});
    const torch::Tensor prediction = torch::rand({2, 3, side, side}).requires_grad_(true);
    const torch::Tensor d = lpips->forward(prediction, target);
    ASSERT_EQ(d.sizes(), torch::IntArrayRef({2})) << side;
    EXPECT_GT(d.min().item<float>(), 0.f) << side;
    EXPECT_EQ(lpips->forward(target, target).abs().max().item<float>(), 0.f) << side;
    d.sum().backward();
    EXPECT_TRUE(torch::isfinite(prediction.grad()).all().item<bool>()) << side;
    EXPECT_GT(prediction.grad().abs().sum().item<float>(), 0.f) << side;
  }
  // Flat images leave many ReLUs dead at a pixel: the gradient must still be finite.
  const torch::Tensor black = torch::zeros({1, 3, 40, 40}, torch::requires_grad());
  lpips->forward(black, torch::full({1, 3, 40, 40}, 0.5)).sum().backward();
  EXPECT_TRUE(torch::isfinite(black.grad()).all().item<bool>());
  EXPECT_THROW(lpips->forward(torch::rand({1, 3, 40, 40}), torch::rand({1, 3, 40, 41})),
               Error);
}

TEST(LpipsNet, BadFileNamesEveryProblem) {
  testing::TempDir dir;
  testing::ExpectError(
      [&] {
        LpipsNet(testing::WriteRandomLpips(dir / "no_lin2.safetensors", "alex", 1.0f,
                                           "lin2.model.1.weight"));
      },
      {"no_lin2.safetensors", "not LPIPS alex weights", "lin2.model.1.weight missing"});
}

}  // namespace
}  // namespace fvs
