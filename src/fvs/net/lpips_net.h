// LPIPS v0.1 (Zhang et al. 2018) as a LibTorch module with frozen weights: the
// evaluation's perceptual metric (eval/lpips.h wraps it for fvs::Image) and the trainer's
// perceptual loss (train/loss.h), differentiable with respect to its input images.
//
// What is computed (the lpips package's recipe): inputs in [0, 1] -> [-1, 1] ->
// (x - shift) / scale; at relu1..relu5 (AlexNet) or relu1_2, relu2_2, relu3_3, relu4_3,
// relu5_3 (VGG16) the features are unit-normalised over channels (eps 1e-10), their
// squared differences weighted by the 1x1 lin<k> layers, averaged over the image, summed
// over the five layers. The file's layout is net/lpips_weights.h.
#pragma once

#include <torch/torch.h>

#include <string>
#include <vector>

#include "fvs/net/lpips_weights.h"

namespace fvs {

class LpipsNetImpl : public torch::nn::Module {
 public:
  // Loads "alex" or "vgg" weights (recognised from the names); throws one fvs::Error
  // naming the file and every missing, mis-shaped or non-finite tensor.
  explicit LpipsNetImpl(const std::string& path);

  // a, b: [B,3,H,W] in [0, 1], same size, on this module's device; returns the [B]
  // distances. Differentiable with respect to a and b (the weights are buffers, never
  // trained). Images smaller than LpipsMinimumSize() on a side are padded to it by
  // replicating their borders, the same for both, so any training crop can be scored.
  torch::Tensor forward(const torch::Tensor& a, const torch::Tensor& b);

  const std::string& network() const { return network_; }

 private:
  // The five tapped feature maps of one batch of images in [0, 1].
  std::vector<torch::Tensor> Features(const torch::Tensor& images01);

  std::string network_;
  std::vector<LpipsConv> layout_;
  std::vector<torch::Tensor> weights_, biases_, lins_;
};
TORCH_MODULE(LpipsNet);

}  // namespace fvs
