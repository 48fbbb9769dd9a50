// The blender of `fvs_agg` (ModelConfig::blender == "aggregate"): no learned encoder,
// per-pixel statistics across the warped sources (as IBRNet aggregates them) and a few
// narrow convolutions, so that it trains on a 2-core CPU. Our design, not the paper's.
//
// Input per source k at every target pixel: its warped colour c_k (zeroed where it does
// not see the pixel), whether it sees it (v_k), its ULR log-weight and weight, c_k minus
// the ULR blend U, and, the same for every source, U itself, the standard deviation of
// the seeing sources' colours, valid_depth and the share of sources that see the pixel.
//   per source (shared weights, the K sources as a batch):
//     conv1x1 (w0) -> half resolution 2 x conv3x3 (w1), up, concatenated, conv1x1 (w0)
//     -> conv3x3 (w0) -> mean and max over the seeing sources, concatenated, conv1x1
//     (w0) -> heads: confidence (1), colour correction (3), both zero at start
//   blend: softmax over k of confidence + ulr_prior * ULR log-weight (log-sum-exp), of
//     the corrected colours (c_k + correction, black where k does not see the pixel)
//   refiner (once per target): the blend, U, the standard deviation, valid_depth and the
//     seeing share -> conv3x3 (w0) -> half resolution 2 x conv3x3 (w1), up,
//     concatenated, conv1x1 (w0) -> conv3x3 (w0) -> conv1x1: a residual added to the
//     blend (zero at start).
// Full-resolution 3x3 convs are few on purpose: at a 128-pixel crop and K = 5 a training
// step is dominated by the per-source full-resolution work.
// With the zero heads the untrained network renders exactly the ULR blend; training
// learns which source to trust where (depth, visibility and colour agreement, angle), a
// sharper choice than the average, colour corrections, and a sharpening of the result.
// Only torch code includes this header.
#pragma once

#include <torch/torch.h>

#include <vector>

#include "fvs/net/model_config.h"
#include "fvs/net/net.h"

namespace fvs {

class AggregateBlenderImpl : public torch::nn::Module {
 public:
  // Uses config.blend_channels (w0, w1) and config.ulr_prior.
  explicit AggregateBlenderImpl(const ModelConfig& config);

  // warped [K,3,H,W] source colours in [-1,1]; valid_depth [1,1,H,W]; valid_warp,
  // ulr_log_weights [K,1,H,W]; H and W any size (padded inside).
  BlendOutput forward(const torch::Tensor& warped, const torch::Tensor& valid_depth,
                      const torch::Tensor& valid_warp,
                      const torch::Tensor& ulr_log_weights);

  // The convolutions run once per source, and those run once per target (FLOP counts).
  std::vector<const ConvUnitImpl*> PerSourceUnits() const;
  std::vector<const ConvUnitImpl*> PerTargetUnits() const;

  // Input channels of the per-source stack and of the refiner.
  static constexpr int kSourceInputs = 17;
  static constexpr int kRefinerInputs = 11;

 private:
  ConvUnit Add(const std::string& name, int in, int out, int kernel, int level,
               std::vector<ConvUnit>* list);

  double ulr_prior_;
  std::vector<ConvUnit> source_, target_;
  ConvUnit s_in_{nullptr}, s_down1_{nullptr}, s_down2_{nullptr}, s_mix_{nullptr},
      s_context_{nullptr}, s_pool_{nullptr}, confidence_{nullptr}, correction_{nullptr};
  ConvUnit r_in_{nullptr}, r_down1_{nullptr}, r_down2_{nullptr}, r_mix_{nullptr},
      r_context_{nullptr}, r_out_{nullptr};
};
TORCH_MODULE(AggregateBlender);

}  // namespace fvs
