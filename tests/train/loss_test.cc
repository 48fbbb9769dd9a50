// The L1 + LPIPS training loss (the real AlexNet weights of ../shared/weights where
// present, random ones otherwise): 0 for identical images, differentiable, and it falls
// when a prediction follows its gradient towards the target; how the loss is chosen.
#include "fvs/train/loss.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cmath>

#include "fvs/util/error.h"
#include "net/lpips_fixture.h"
#include "support/test_support.h"

namespace fvs {
namespace {

// The official weights where the shared folder has them, else random ones (*which says).
LpipsNet LoadTestLpips(const testing::TempDir& dir, std::string* which) {
  std::string why_skip;
  std::string path = testing::SharedFile("weights/lpips_alex.safetensors", &why_skip);
  *which = path.empty() ? "random weights (" + why_skip + ")" : path;
  if (path.empty()) path = testing::WriteRandomLpips(dir / "alex.safetensors", "alex");
  return LpipsNet(path);
}

// A smooth image in [0, 1] with some structure for the features to see.
torch::Tensor Pattern(int64_t side, double phase) {
  const torch::Tensor y = torch::arange(side).view({1, 1, side, 1}).to(torch::kFloat);
  const torch::Tensor x = torch::arange(side).view({1, 1, 1, side}).to(torch::kFloat);
  const torch::Tensor c = torch::arange(3).view({1, 3, 1, 1}).to(torch::kFloat);
  return 0.5 + 0.4 * torch::sin(0.23 * x + 0.11 * y + c + phase);
}

TEST(LpipsLoss, ZeroForEqualImagesAndFallsAlongItsGradient) {
  torch::set_num_threads(2);
  testing::TempDir dir;
  std::string which;
  LossOptions options;
  options.kind = "l1+lpips";
  options.lpips = LoadTestLpips(dir, &which);
  TrainingLoss loss(options, torch::kCPU);
  EXPECT_EQ(loss.Name(), "l1+lpips");
  EXPECT_EQ(loss.SecondTermName(), "lpips");

  const torch::Tensor target = Pattern(64, 0.0);
  const LossValue same = loss(target, target);
  EXPECT_EQ(same.l1, 0.0) << which;
  EXPECT_EQ(same.second, 0.0) << which;

  // A prediction a phase away, its pixels moved by a few Adam steps (each pixel about
  // 0.02 a step, whatever the gradient's scale).
  torch::Tensor prediction = Pattern(64, 1.2).requires_grad_(true);
  torch::optim::Adam adam({prediction}, torch::optim::AdamOptions(0.02));
  double first = 0, first_lpips = 0, last = 0, last_lpips = 0;
  for (int step = 0; step < 8; ++step) {
    adam.zero_grad();
    const LossValue value = loss(prediction, target);
    EXPECT_NEAR(value.total.item<double>(), value.l1 + value.second, 1e-5);
    value.total.backward();
    ASSERT_TRUE(torch::isfinite(prediction.grad()).all().item<bool>()) << which;
    EXPECT_GT(prediction.grad().abs().sum().item<float>(), 0.f) << which;
    last = value.l1 + value.second;
    last_lpips = value.second;
    if (step == 0) {
      first = last;
      first_lpips = last_lpips;
    }
    adam.step();
  }
  EXPECT_GT(first_lpips, 0.0) << which;
  EXPECT_LT(last, 0.9 * first) << which << ": " << first << " -> " << last;
  EXPECT_LT(last_lpips, first_lpips) << which;

  // The weight scales the second term only.
  options.lpips_weight = 2.0;
  TrainingLoss doubled(options, torch::kCPU);
  const torch::Tensor other = Pattern(64, 0.4);
  EXPECT_NEAR(doubled(other, target).second, 2 * loss(other, target).second, 1e-5);

  // L1 + (1 - SSIM) + LPIPS: the second term is the sum of both.
  options.lpips_weight = 1.0;
  options.kind = "l1+ssim+lpips";
  TrainingLoss both(options, torch::kCPU);
  EXPECT_EQ(both.SecondTermName(), "1-ssim+lpips");
  EXPECT_EQ(both(target, target).second, 0.0);
  EXPECT_NEAR(both(other, target).second,
              loss(other, target).second + 1.0 - Ssim(other, target).item<double>(),
              1e-5);
}

TEST(LpipsLoss, AutoPrefersVgg19ThenLpipsThenSsim) {
  EXPECT_EQ(ChooseLoss("auto", false, false), "l1+ssim");
  EXPECT_EQ(ChooseLoss("auto", false, true), "l1+lpips");
  EXPECT_EQ(ChooseLoss("auto", true, true), "l1+vgg19");
  EXPECT_EQ(ChooseLoss("l1+ssim", true, true), "l1+ssim");
  testing::ExpectError(
      [] { ChooseLoss("l1+lpips", false, false); },
      {"--Train.loss", "l1+lpips needs LPIPS weights", "FVS_LPIPS_PATH"});
  EXPECT_EQ(ChooseLoss("l1+ssim+lpips", false, true), "l1+ssim+lpips");
  testing::ExpectError([] { ChooseLoss("l1+ssim+lpips", false, false); },
                       {"l1+ssim+lpips needs LPIPS weights"});
  testing::ExpectError([] { ChooseLoss("l1+vgg19", false, true); },
                       {"--Train.loss", "--vgg19_path"});
  LossOptions no_network;
  no_network.kind = "l1+lpips";
  EXPECT_THROW(TrainingLoss(no_network, torch::kCPU), Error);
}

// The choice term is the weights' expectation of each source's own error over the seen
// pixels: the closest source alone scores its error, an even split the mean of the two,
// unseen pixels do not count, and its gradient moves weight towards the closest source.
TEST(ChoiceLoss, ExpectsEachSourcesErrorAndPullsWeightToTheClosest) {
  const torch::Tensor target = torch::full({1, 3, 4, 4}, 0.5);
  // Source 0 is off by 0.1 and source 1 by 0.3 (in [0, 1]); colours in [-1, 1].
  const torch::Tensor rgb = torch::cat({torch::full({1, 3, 4, 4}, 2 * 0.6 - 1.0),
                                        torch::full({1, 3, 4, 4}, 2 * 0.2 - 1.0)});
  torch::Tensor seen = torch::ones({1, 1, 4, 4});
  const torch::Tensor first =
      torch::cat({torch::ones({1, 1, 4, 4}), torch::zeros({1, 1, 4, 4})});
  EXPECT_NEAR(ChoiceLoss(first, rgb, target, seen).item<double>(), 0.1, 1e-6);
  EXPECT_NEAR(ChoiceLoss(1.0 - first, rgb, target, seen).item<double>(), 0.3, 1e-6);
  const torch::Tensor even = torch::full({2, 1, 4, 4}, 0.5);
  EXPECT_NEAR(ChoiceLoss(even, rgb, target, seen).item<double>(), 0.2, 1e-6);
  // Half the pixels unseen, where source 1 would be perfect: they do not count.
  seen.narrow(3, 0, 2).zero_();
  torch::Tensor rgb2 = rgb.clone();
  rgb2[1].narrow(2, 0, 2) = 0.0;  // 0.5 in [0, 1]: exact, but unseen
  EXPECT_NEAR(ChoiceLoss(1.0 - first, rgb2, target, seen).item<double>(), 0.3, 1e-6);
  // Gradient through a softmax: the logit of the closer source rises.
  const torch::Tensor logits = torch::zeros({2, 1, 4, 4}, torch::requires_grad());
  ChoiceLoss(torch::softmax(logits, 0), rgb, target, torch::ones({1, 1, 4, 4}))
      .backward();
  EXPECT_LT(logits.grad()[0].sum().item<double>(), 0);
  EXPECT_GT(logits.grad()[1].sum().item<double>(), 0);
}

}  // namespace
}  // namespace fvs
