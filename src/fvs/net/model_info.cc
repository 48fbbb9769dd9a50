// Size and cost of a network: parameters, analytic FLOPs per source, and the time of one
// K = 1 forward on this machine (numbers come with their cost).
#include <cstdio>

#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {

ModelInfo DescribeModel(FvsNet& net, int width, int height, bool time_forward) {
  Require(width > 0 && height > 0 && width <= 16384 && height <= 16384, "model info",
          "size must be in [1, 16384] x [1, 16384], got " + std::to_string(width) + "x" +
              std::to_string(height));
  ModelInfo info;
  info.config = net->config();
  info.width = width;
  info.height = height;
  info.encoder_parameters = net->EncoderParameterCount();
  info.blender_parameters = net->BlenderParameterCount();
  info.encode_flops = net->EncodeFlops(height, width);
  info.blend_flops = net->BlendFlops(height, width);
  if (!time_forward) return info;

  torch::NoGradGuard no_grad;
  const bool was_training = net->is_training();
  net->eval();
  torch::manual_seed(0);
  const torch::Tensor image = torch::rand({1, 3, height, width}) * 2 - 1;
  const torch::Tensor valid_depth = torch::ones({1, 1, height, width});
  const torch::Tensor valid_warp = torch::ones({1, 1, height, width});
  Timer timer;
  const torch::Tensor features = net->Encode(image);
  info.encode_seconds = timer.Seconds();
  timer.Restart();
  const torch::Tensor warped = WarpFeatures(features, IdentityGrid(1, height, width));
  const torch::Tensor ulr_log_weights = torch::zeros({1, 1, height, width});
  const BlendOutput out = net->Blend(warped, valid_depth, valid_warp, ulr_log_weights);
  info.blend_seconds = timer.Seconds();
  Require(torch::isfinite(out.rgb).all().item<bool>(), "model info",
          "the forward pass produced NaN or Inf");
  net->train(was_training);
  return info;
}

std::string FormatModelInfo(const ModelInfo& info) {
  char line[512];
  std::string s;
  const ModelConfig& c = info.config;
  std::snprintf(
      line, sizeof(line),
      "%s: features %d, masks %s, gru %s, soft-argmax %s, inf-depth %s, "
      "separable %s, rgb skip %s, mask prior %g, ulr prior %g (k %d, resolution %g)\n",
      c.variant.c_str(), c.feature_channels, c.use_masks ? "yes" : "no",
      c.use_gru ? "yes" : "no", c.soft_argmax ? "yes" : "no", c.inf_depth ? "yes" : "no",
      c.depthwise_separable ? "yes" : "no", c.rgb_skip ? "yes" : "no", c.mask_prior,
      c.ulr_prior, c.ulr_num_blend, c.ulr_resolution_weight);
  s += line;
  std::snprintf(
      line, sizeof(line), "  parameters: encoder %lld, blender %lld, total %lld\n",
      static_cast<long long>(info.encoder_parameters),
      static_cast<long long>(info.blender_parameters),
      static_cast<long long>(info.encoder_parameters + info.blender_parameters));
  s += line;
  std::snprintf(line, sizeof(line),
                "  GFLOPs per source at %dx%d: encode %.2f, blend %.2f, total %.2f\n",
                info.width, info.height, info.encode_flops * 1e-9,
                info.blend_flops * 1e-9, (info.encode_flops + info.blend_flops) * 1e-9);
  s += line;
  if (info.encode_seconds >= 0) {
    std::snprintf(
        line, sizeof(line),
        "  time of one K=1 forward (CPU, %d threads): encode %.3f s, warp+blend "
        "%.3f s\n",
        torch::get_num_threads(), info.encode_seconds, info.blend_seconds);
    s += line;
  }
  return s;
}

}  // namespace fvs
