#include "tools/headroom/depth_stereo.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "tools/headroom/consensus.h"
#include "tools/headroom/depth_sweep.h"

namespace fvs {
namespace {

// One scanline path of semi-global matching: `n` pixels from `start`, `stride` apart (in
// pixels of an h x w plane), D candidates `plane` apart in `cost` and `sum`.
void AggregatePath(const float* cost, float* sum, int64_t start, int64_t stride,
                   int64_t n, int64_t depth_count, int64_t plane, float p1, float p2,
                   std::vector<float>* previous, std::vector<float>* current) {
  for (int64_t i = 0; i < n; ++i) {
    const int64_t p = start + i * stride;
    float best_previous = std::numeric_limits<float>::infinity();
    if (i > 0) {
      for (int64_t d = 0; d < depth_count; ++d) {
        best_previous = std::min(best_previous, (*previous)[d]);
      }
    }
    for (int64_t d = 0; d < depth_count; ++d) {
      float path = 0;
      if (i > 0) {
        path = std::min((*previous)[d], best_previous + p2);
        if (d > 0) path = std::min(path, (*previous)[d - 1] + p1);
        if (d + 1 < depth_count) path = std::min(path, (*previous)[d + 1] + p1);
        path -= best_previous;
      }
      (*current)[d] = cost[d * plane + p] + path;
      sum[d * plane + p] += (*current)[d];
    }
    std::swap(*previous, *current);
  }
}

// Luminance [K,1,h,w] of colours [K,3,h,w].
torch::Tensor Luminance(const torch::Tensor& colours) { return colours.mean(1, true); }

// 1 - the normalised cross-correlation of each source's luminance `b` [K,1,h,w] with the
// reference's `a` [1,1,h,w] over the window, over the pixels both have (`valid`
// [K,1,h,w]); 1 where either window is flatter than `min_texture` or less than half of
// it is valid. Plus `absolute_weight` x the window's mean |a - b| / 0.1.
torch::Tensor CorrelationCost(const torch::Tensor& a, const torch::Tensor& b,
                              const torch::Tensor& valid, int radius, double min_texture,
                              double absolute_weight) {
  const torch::Tensor n = BoxMeanInImage(valid, radius);
  const torch::Tensor count = n.clamp_min(1e-6);
  const torch::Tensor mean_a = BoxMeanInImage(a * valid, radius) / count;
  const torch::Tensor mean_b = BoxMeanInImage(b * valid, radius) / count;
  const torch::Tensor var_a =
      (BoxMeanInImage(a * a * valid, radius) / count - mean_a * mean_a).clamp_min(0);
  const torch::Tensor var_b =
      (BoxMeanInImage(b * b * valid, radius) / count - mean_b * mean_b).clamp_min(0);
  const torch::Tensor covariance =
      BoxMeanInImage(a * b * valid, radius) / count - mean_a * mean_b;
  const double floor = min_texture * min_texture;
  // At least half the window valid, and texture in both.
  const torch::Tensor usable = (n > 0.5) & (var_a > floor) & (var_b > floor);
  const torch::Tensor ncc =
      (covariance / (var_a * var_b).sqrt().clamp_min(1e-12)).clamp(-1, 1);
  torch::Tensor cost = torch::where(usable, 1 - ncc, torch::ones_like(ncc));
  if (absolute_weight > 0) {
    cost = cost +
           absolute_weight / 0.1 * BoxMeanInImage((a - b).abs() * valid, radius) / count;
  }
  return cost;
}

}  // namespace

void DepthStereoOptions::Check() const {
  Require(steps >= 1 && steps <= 32, "DepthStereoOptions", "steps must be in [1, 32]");
  Require(std::isfinite(max_relative) && max_relative > 0 && max_relative < 0.5,
          "DepthStereoOptions", "max_relative must be in (0, 0.5)");
  Require(radius >= 1 && radius <= 16, "DepthStereoOptions", "radius must be in [1, 16]");
  Require(std::isfinite(min_texture) && min_texture >= 0 && std::isfinite(prior) &&
              prior >= 0,
          "DepthStereoOptions", "min_texture and prior must be finite and >= 0");
  Require(std::isfinite(absolute_weight) && absolute_weight >= 0, "DepthStereoOptions",
          "absolute_weight must be finite and >= 0");
  Require(std::isfinite(p1) && std::isfinite(p2) && p1 >= 0 && p2 >= p1,
          "DepthStereoOptions", "the penalties need 0 <= p1 <= p2, finite");
}

torch::Tensor SemiGlobalAggregate(const torch::Tensor& cost, double p1, double p2) {
  Require(cost.dim() == 3 && cost.size(0) >= 1, "SemiGlobalAggregate",
          "the cost volume must be [D,h,w]");
  const torch::Tensor c = cost.to(torch::kFloat).contiguous();
  Require(torch::isfinite(c).all().item<bool>(), "SemiGlobalAggregate",
          "the cost volume must be finite");
  const int64_t depth_count = c.size(0), h = c.size(1), w = c.size(2);
  torch::Tensor sum = torch::zeros_like(c);
  const float* in = c.data_ptr<float>();
  float* out = sum.data_ptr<float>();
  std::vector<float> previous(depth_count), current(depth_count);
  const float a = static_cast<float>(p1), b = static_cast<float>(p2);
  const int64_t plane = h * w;
  for (int64_t y = 0; y < h; ++y) {  // left to right, right to left
    AggregatePath(in, out, y * w, 1, w, depth_count, plane, a, b, &previous, &current);
    AggregatePath(in, out, y * w + w - 1, -1, w, depth_count, plane, a, b, &previous,
                  &current);
  }
  for (int64_t x = 0; x < w; ++x) {  // top to bottom, bottom to top
    AggregatePath(in, out, x, w, h, depth_count, plane, a, b, &previous, &current);
    AggregatePath(in, out, (h - 1) * w + x, -w, h, depth_count, plane, a, b, &previous,
                  &current);
  }
  return sum;
}

torch::Tensor DepthStereoBlend(const PackedScene& scene, const TrainingSample& s,
                               const SampleWarpOptions& settings,
                               const DepthStereoOptions& options, torch::Tensor* chosen) {
  options.Check();
  CheckRefinableSample(scene, s);
  torch::NoGradGuard no_grad;
  const torch::Tensor& seen = s.warp.valid_warp;  // [K,1,h,w]
  const int64_t h = seen.size(2), w = seen.size(3);
  // Normalised ULR weights among the seeing sources, fixed over the sweep; the reference
  // of each pixel is its heaviest seeing source.
  const torch::Tensor weights = SeenWeights(s.warp.ulr_log_weights, seen);
  const torch::Tensor reference = weights.argmax(0, true);  // [1,1,h,w]
  const torch::Tensor others =
      seen * (torch::arange(seen.size(0)).view({-1, 1, 1, 1}) != reference);
  const torch::Tensor sweepable = Refinable(s);

  std::vector<torch::Tensor> blends, costs;
  for (int i = -options.steps; i <= options.steps; ++i) {
    const double change = options.max_relative * i / options.steps;
    const torch::Tensor grid = GridAtScaledDepth(scene, s, settings, change);
    const torch::Tensor in_frame =
        (grid.abs() <= 1).all(-1).unsqueeze(1).to(torch::kFloat);  // [K,1,h,w]
    const torch::Tensor colours =
        torch::nan_to_num((WarpFeatures(s.source_rgb, grid) + 1) * 0.5, 0, 0, 0);
    blends.push_back((weights * colours).sum(0, true));  // [1,3,h,w]
    const torch::Tensor luminance = Luminance(colours);
    const torch::Tensor reference_luminance = luminance.gather(0, reference);
    const torch::Tensor reference_in_frame = in_frame.gather(0, reference);
    const torch::Tensor pair_cost =
        CorrelationCost(reference_luminance, luminance, in_frame * reference_in_frame,
                        options.radius, options.min_texture, options.absolute_weight);
    const torch::Tensor pair_weights = weights * others * in_frame;
    const torch::Tensor total = pair_weights.sum(0, true);
    torch::Tensor cost = torch::where(
        total > 1e-6, (pair_weights * pair_cost).sum(0, true) / total.clamp_min(1e-6),
        torch::ones_like(total));
    cost = torch::where(sweepable, cost, torch::ones_like(cost));
    const double away = static_cast<double>(std::abs(i)) / options.steps;
    costs.push_back(torch::nan_to_num(cost, 1, 1, 1) + options.prior * away);
  }
  const torch::Tensor volume = torch::cat(costs, 0).squeeze(1);  // [D,h,w]
  torch::Tensor best = SemiGlobalAggregate(volume, options.p1, options.p2)
                           .argmin(0, true)
                           .unsqueeze(0);  // [1,1,h,w]
  best = torch::where(sweepable, best, torch::full_like(best, options.steps));
  const torch::Tensor stacked = torch::cat(blends, 0);  // [D,3,h,w]
  const torch::Tensor blend = stacked.gather(0, best.expand({1, 3, h, w}));
  if (chosen != nullptr) {
    *chosen = (best.to(torch::kFloat) - options.steps) *
              static_cast<float>(options.max_relative / options.steps);
  }
  return torch::nan_to_num(blend, 0, 0, 0).clamp(0, 1);
}

}  // namespace fvs
