#include "tools/headroom/depth_sweep.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "tools/headroom/consensus.h"

namespace fvs {
void DepthSweepOptions::Check() const {
  Require(steps >= 1 && steps <= 32, "DepthSweepOptions", "steps must be in [1, 32]");
  Require(std::isfinite(max_relative) && max_relative > 0 && max_relative < 0.5,
          "DepthSweepOptions", "max_relative must be in (0, 0.5)");
  Require(radius >= 0 && radius <= 16, "DepthSweepOptions", "radius must be in [0, 16]");
  Require(std::isfinite(prior) && prior >= 0 && std::isfinite(relative_prior) &&
              relative_prior >= 0,
          "DepthSweepOptions", "prior and relative_prior must be finite and >= 0");
}

void CheckRefinableSample(const PackedScene& scene, const TrainingSample& s) {
  Require(s.warp.ulr_log_weights.defined(), "depth refinement",
          "the sample has no ULR log-weights");
  Require(s.warp.valid_warp.size(2) == scene.height() &&
              s.warp.valid_warp.size(3) == scene.width(),
          "depth refinement", "needs a full-size sample");
}

torch::Tensor GridAtScaledDepth(const PackedScene& scene, const TrainingSample& s,
                                const SampleWarpOptions& settings, double change) {
  CheckRefinableSample(scene, s);
  if (change == 0) return s.warp.grid;
  const torch::Tensor idx = torch::tensor(
      std::vector<int64_t>(s.sources.begin(), s.sources.end()), torch::kLong);
  SampleWarpOptions geometry_only = settings;
  geometry_only.ulr_log_weights = false;
  return ComputeTrainingWarp(scene.K[s.target], scene.R[s.target], scene.t[s.target],
                             scene.depths[s.target] * (1 + change),
                             scene.K.index_select(0, idx), scene.R.index_select(0, idx),
                             scene.t.index_select(0, idx),
                             scene.depths.index_select(0, idx), geometry_only)
      .grid;
}

torch::Tensor Refinable(const TrainingSample& s) {
  return (s.warp.valid_warp.sum(0, true) >= 2) & (s.warp.valid_depth > 0);
}

torch::Tensor DepthSweepBlend(const PackedScene& scene, const TrainingSample& s,
                              const SampleWarpOptions& settings,
                              const DepthSweepOptions& options, torch::Tensor* chosen) {
  options.Check();
  CheckRefinableSample(scene, s);
  torch::NoGradGuard no_grad;
  const torch::Tensor& seen = s.warp.valid_warp;  // [K,1,h,w]
  const int64_t h = seen.size(2), w = seen.size(3);
  // Normalised ULR weights among the seeing sources, fixed over the sweep.
  const torch::Tensor weights = SeenWeights(s.warp.ulr_log_weights, seen);
  const torch::Tensor sweepable = Refinable(s);

  torch::Tensor best_cost =
      torch::full({1, 1, h, w}, std::numeric_limits<float>::infinity());
  torch::Tensor best_blend, best_change = torch::zeros({1, 1, h, w});
  for (int i = -options.steps; i <= options.steps; ++i) {
    const double change = options.max_relative * i / options.steps;
    const torch::Tensor grid = GridAtScaledDepth(scene, s, settings, change);
    const torch::Tensor colours =
        torch::nan_to_num((WarpFeatures(s.source_rgb, grid) + 1) * 0.5, 0, 0, 0);
    const torch::Tensor blend = (weights * colours).sum(0, true);  // [1,3,h,w]
    const torch::Tensor variance =
        (weights * (colours - blend).pow(2)).sum(0, true).sum(1, true);
    const double away = static_cast<double>(std::abs(i)) / options.steps;
    const torch::Tensor cost =
        torch::nan_to_num(BoxMeanInImage(variance, options.radius), 1e3) *
            (1 + options.relative_prior * away) +
        options.prior * away;
    if (i == -options.steps) best_blend = blend;
    const torch::Tensor better =
        (cost < best_cost) & (i == 0 ? torch::ones_like(sweepable) : sweepable);
    best_cost = torch::where(better, cost, best_cost);
    best_blend = torch::where(better, blend, best_blend);
    best_change =
        torch::where(better, torch::full_like(best_change, change), best_change);
  }
  // Pixels no candidate could score keep the proxy's depth (their blend at i = 0 won).
  if (chosen != nullptr) *chosen = best_change;
  return torch::nan_to_num(best_blend, 0, 0, 0).clamp(0, 1);
}

}  // namespace fvs
