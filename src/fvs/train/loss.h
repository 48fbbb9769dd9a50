// Training losses on images in [0, 1] (ChooseLoss picks one):
//   l1+ssim    L1 + (1 - SSIM)  (SSIM with the 11x11 Gaussian window, sigma 1.5, valid
//                                region only: no zero padding at the borders)
//   l1+lpips   L1 + w LPIPS-alex (net/lpips_net.h; w = --Train.lpips_weight, 1): the
//              perceptual loss whose weights we have (../shared/weights/README.md)
//   l1+vgg19   L1 + perceptual: L1 between VGG19 features at relu1_2, relu2_2, relu3_2,
//              relu4_2, relu5_2 weighted 1, 0.75, 0.5, 0.5, 1 (Riegler & Koltun 2020).
// VGG19 weights cannot be downloaded here, so they come from a safetensors file holding
// torchvision's vgg19 `features` state dict (names "features.<i>.weight"/".bias", i = 0,
// 2, 5, ..., 30; doc/training.md has the one-line conversion).
#pragma once

#include <torch/torch.h>

#include <string>
#include <vector>

#include "fvs/net/lpips_net.h"

namespace fvs {

// Mean SSIM of a and b ([B,C,H,W], H and W >= 11), differentiable.
torch::Tensor Ssim(const torch::Tensor& a, const torch::Tensor& b);

// The first 30 layers of torchvision's vgg19().features (conv5_2 + ReLU), frozen.
class Vgg19FeaturesImpl : public torch::nn::Module {
 public:
  Vgg19FeaturesImpl();
  // Images in [0,1], [B,3,H,W]; returns relu1_2, relu2_2, relu3_2, relu4_2, relu5_2.
  std::vector<torch::Tensor> forward(const torch::Tensor& images01);
  // Loads "features.<i>.weight/bias" (also accepted without the "features." prefix) from
  // a safetensors file; throws fvs::Error listing what is missing or mis-shaped.
  void Load(const std::string& path);
  // Names and shapes the file must hold (for docs, tests and error messages).
  static std::vector<std::pair<std::string, std::vector<int64_t>>> ExpectedTensors();

 private:
  std::vector<torch::nn::Conv2d> convs_;
};
TORCH_MODULE(Vgg19Features);

struct LossValue {
  torch::Tensor total;  // differentiable scalar: l1 + second (+ choice, the trainer's)
  double l1 = 0;
  double second = 0;  // 1 - SSIM, w x LPIPS, both, or the VGG19 term
  double choice = 0;  // w x ChoiceLoss, when the trainer adds it
  // The value of `total`, as a number (progress lines, the card's final loss).
  double Value() const { return l1 + second + choice; }
};

// The choice term of a soft-argmax blend: the mean over `seen` pixels of the blend
// weights' expectation of each source's own error, sum_k w_k mean_c |c_k - y|, with
// per-source colours c_k in [-1, 1] ([K,3,H,W]; scaled to [0, 1] here), weights [K,1,H,W]
// and the target y [1,3,H,W] in [0, 1]; seen [1,1,H,W] (> 0 = counted). Why beside the
// image loss: the image loss of a blend cannot tell a sharp choice of the right source
// from an average that happens to land near the photo, and under noise it prefers the
// average; this term is lowest when the weight sits on the source closest to the photo
// and is the same for any weighting of sources that are equally right (noise), so it
// teaches the choice without undoing the average where nothing tells sources apart.
torch::Tensor ChoiceLoss(const torch::Tensor& weights,
                         const torch::Tensor& per_source_rgb,
                         const torch::Tensor& target01, const torch::Tensor& seen);

// The loss of a run: `requested` (auto, l1+ssim, l1+lpips, l1+vgg19) made concrete.
// auto: l1+vgg19 when a VGG19 file is given (asking for it is the stronger wish), else
// l1+lpips when LPIPS weights are loaded, else l1+ssim. Throws fvs::Error when an
// explicit choice lacks its weights.
std::string ChooseLoss(const std::string& requested, bool have_vgg19, bool have_lpips);
// l1+lpips and l1+ssim+lpips (L1 + (1 - SSIM) + w x LPIPS) need the LPIPS network.
bool LossUsesLpips(const std::string& kind);

struct LossOptions {
  // l1+ssim, l1+lpips, l1+ssim+lpips or l1+vgg19 (ChooseLoss)
  std::string kind = "l1+ssim";
  std::string vgg19_path;   // l1+vgg19: the weights file
  LpipsNet lpips{nullptr};  // l1+lpips: the loaded network (validation shares it)
  double lpips_weight = 1.0;
};

class TrainingLoss {
 public:
  // Loads VGG19 (l1+vgg19) and moves the networks onto `device`. Throws fvs::Error for
  // an unknown kind, a bad VGG19 file or l1+lpips without a network.
  TrainingLoss(const LossOptions& options, const torch::Device& device);
  // The mean over the batch of prediction and target, [B,3,H,W] in [0, 1].
  LossValue operator()(const torch::Tensor& prediction01, const torch::Tensor& target01);
  const std::string& Name() const { return options_.kind; }
  // The second term in progress lines: "1-ssim", "lpips" or "vgg".
  std::string SecondTermName() const;

 private:
  torch::Tensor SecondTerm(const torch::Tensor& prediction01,
                           const torch::Tensor& target01);

  LossOptions options_;
  Vgg19Features vgg_{nullptr};
};

}  // namespace fvs
