// Training losses on images in [0, 1]:
//   default      L1 + (1 - SSIM)  (SSIM with the 11x11 Gaussian window, sigma 1.5, valid
//                                  region only: no zero padding at the borders)
//   with VGG19   L1 + perceptual: L1 between VGG19 features at relu1_2, relu2_2, relu3_2,
//                relu4_2, relu5_2 weighted 1, 0.75, 0.5, 0.5, 1 (Riegler & Koltun 2020).
// VGG19 weights cannot be downloaded here, so they come from a safetensors file holding
// torchvision's vgg19 `features` state dict (names "features.<i>.weight"/".bias", i = 0,
// 2, 5, ..., 30; doc/training.md has the one-line conversion).
#pragma once

#include <torch/torch.h>

#include <string>
#include <vector>

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
  torch::Tensor total;  // differentiable scalar
  double l1 = 0;
  double second = 0;  // 1 - SSIM, or the perceptual term
};

class TrainingLoss {
 public:
  // Empty vgg19_path: L1 + SSIM. Otherwise loads VGG19 onto `device`.
  TrainingLoss(const std::string& vgg19_path, const torch::Device& device);
  LossValue operator()(const torch::Tensor& prediction01, const torch::Tensor& target01);
  bool perceptual() const { return !vgg_.is_empty(); }
  std::string Name() const { return perceptual() ? "l1+vgg19" : "l1+ssim"; }

 private:
  Vgg19Features vgg_{nullptr};
};

}  // namespace fvs
