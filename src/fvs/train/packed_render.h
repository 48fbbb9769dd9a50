// Rendering a whole view of a packed scene with the network and with the `ulr` baseline,
// as the trainer's validation does, timed in parts; shared by the validation
// (Trainer::Validate) and the trainer-only render benchmark (train/render_benchmark.h).
#pragma once

#include <torch/torch.h>

#include <vector>

#include "fvs/net/lpips_net.h"
#include "fvs/net/net.h"
#include "fvs/train/data.h"

namespace fvs {

// A sample's tensors on the device.
struct DeviceSample {
  torch::Tensor target, sources, grid, valid_depth, valid_warp, ulr_log_weights;
};
DeviceSample ToDevice(const TrainingSample& s, const torch::Device& device);

// PSNR, SSIM and (with LPIPS weights) LPIPS of a [1,3,H,W] image in [0, 1].
struct ViewScores {
  double psnr = 0, ssim = 0, lpips = 0;
};
ViewScores ScoreView(const torch::Tensor& image, const torch::Tensor& target,
                     LpipsNet lpips);

struct PackedViewRender {
  torch::Tensor target;      // [1,3,H,W] in [0,1], the photo (on the device)
  torch::Tensor prediction;  // the network's, holes filled, fp32 in [0,1]
  torch::Tensor ulr;         // the ULR blend of the same warps, holes filled
  // Seconds: sample_s the CPU warp (MakeSample: grid, masks, ULR weights, gathered
  // sources); warp_s their copy to the device and the feature warp (grid_sample);
  // network_s Encode + Blend; rest_s hole filling and the colour mapping. Each part ends
  // with a CUDA synchronisation on a GPU.
  double sample_s = 0, warp_s = 0, network_s = 0, rest_s = 0;
};

// Renders `target` of `scene` from `sources` at the scene's size. `dtype` is the
// network's precision: kFloat32, or kBFloat16 / kHalf with the network already cast to
// it (its input cast, the features warped in fp32 and cast back, as the renderer does);
// the output is fp32. The ulr image only when `with_ulr`. Call under NoGradGuard or
// InferenceMode with the network in eval().
PackedViewRender RenderPackedView(FvsNet& net, const PackedScene& scene, int target,
                                  const std::vector<int>& sources,
                                  const SampleWarpOptions& warp, const torch::Device& device,
                                  torch::ScalarType dtype, bool with_ulr);

// The scene at another size: photos resized bilinearly, depths by nearest neighbour (no
// mixing of surface and no surface), intrinsics scaled per axis (COLMAP's pixel
// convention scales exactly). For timing at the render benchmark's sizes; enlarging a
// quarter-scale pack adds no detail.
PackedScene ResizePackedScene(const PackedScene& scene, int width, int height);

}  // namespace fvs
