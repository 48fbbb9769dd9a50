#include "fvs/train/packed_render.h"

#include <algorithm>
#include <cmath>

#include "fvs/train/loss.h"
#include "fvs/util/progress.h"

namespace fvs {

DeviceSample ToDevice(const TrainingSample& s, const torch::Device& device) {
  auto to = [&](const torch::Tensor& t) { return t.defined() ? t.to(device) : t; };
  return {to(s.target_rgb),       to(s.source_rgb),      to(s.warp.grid),
          to(s.warp.valid_depth), to(s.warp.valid_warp), to(s.warp.ulr_log_weights)};
}

ViewScores ScoreView(const torch::Tensor& image, const torch::Tensor& target,
                     LpipsNet lpips) {
  ViewScores scores;
  const double mse = (image - target).pow(2).mean().item<double>();
  scores.psnr = 10.0 * std::log10(1.0 / std::max(mse, 1e-10));
  scores.ssim = Ssim(image, target).item<double>();
  if (!lpips.is_empty()) scores.lpips = lpips->forward(image, target).item<double>();
  return scores;
}

PackedViewRender RenderPackedView(FvsNet& net, const PackedScene& scene, int target,
                                  const std::vector<int>& sources,
                                  const SampleWarpOptions& warp, const torch::Device& device,
                                  torch::ScalarType dtype, bool with_ulr) {
  auto sync = [&] {
    if (device.is_cuda()) torch::cuda::synchronize();
  };
  PackedViewRender r;
  Timer timer;
  const TrainingSample sample =
      MakeSample(scene, target, sources, 0, 0, scene.width(), scene.height(), warp);
  r.sample_s = timer.Seconds();
  timer.Restart();
  const DeviceSample s = ToDevice(sample, device);
  const bool cast = dtype != torch::kFloat32;
  sync();
  const double copy_s = timer.Seconds();
  timer.Restart();
  torch::Tensor features = net->Encode(cast ? s.sources.to(dtype) : s.sources);
  sync();
  r.network_s = timer.Seconds();
  timer.Restart();
  // Sampling positions need fp32: warp in fp32 (fvs_method.cc does the same).
  torch::Tensor warped = WarpFeatures(cast ? features.to(torch::kFloat32) : features, s.grid);
  if (cast) warped = warped.to(dtype);
  sync();
  r.warp_s = copy_s + timer.Seconds();
  timer.Restart();
  const BlendOutput out = net->Blend(warped, s.valid_depth, s.valid_warp, s.ulr_log_weights);
  sync();
  r.network_s += timer.Seconds();
  timer.Restart();
  const torch::Tensor covered = s.valid_warp.sum(0, true) > 0;
  // As the renderer: holes (no source sees the pixel) filled from around them.
  r.prediction = FillHolesOf(((out.rgb.to(torch::kFloat32) + 1.0) * 0.5).clamp(0.0, 1.0),
                             covered, s.valid_depth);
  sync();
  r.rest_s = timer.Seconds();
  r.target = s.target;
  if (with_ulr) {
    r.ulr = FillHolesOf(
        (((SoftmaxWeights(s.ulr_log_weights) * WarpFeatures(s.sources, s.grid))
              .sum(0, true) +
          1.0) *
         0.5)
            .clamp(0.0, 1.0),
        covered, s.valid_depth);
  }
  return r;
}

PackedScene ResizePackedScene(const PackedScene& scene, int width, int height) {
  namespace F = torch::nn::functional;
  PackedScene r = scene;
  const double sx = static_cast<double>(width) / scene.width();
  const double sy = static_cast<double>(height) / scene.height();
  const std::vector<int64_t> size = {height, width};
  r.images = F::interpolate(scene.images.to(torch::kFloat32),
                            F::InterpolateFuncOptions()
                                .size(size)
                                .mode(torch::kBilinear)
                                .align_corners(false))
                 .round()
                 .clamp(0, 255)
                 .to(torch::kUInt8);
  r.depths = F::interpolate(scene.depths.unsqueeze(1),
                            F::InterpolateFuncOptions().size(size).mode(torch::kNearest))
                 .squeeze(1)
                 .contiguous();
  r.K = scene.K.clone();
  r.K.select(1, 0).mul_(sx);  // fx, skew, cx
  r.K.select(1, 1).mul_(sy);  // fy, cy
  return r;
}

}  // namespace fvs
