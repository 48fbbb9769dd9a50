// The geometric front end every method shares: target depth from the proxy mesh, the
// top-K sources by overlap, and one warping map per selected source (same target depth
// for all).
#pragma once

#include <vector>

#include "fvs/geometry/warp.h"
#include "fvs/render/method.h"

namespace fvs {

struct PreparedTarget {
  Image depth;                       // target depth (0 = no surface)
  std::vector<SourceScore> sources;  // best first, only sources that see something
  std::vector<WarpMap> warps;        // one per source, same order
  RenderTimings timings;             // depth_s, selection_s, warp_s filled
};

// The top k of `ranked` (every source that sees something, best first) after the
// counts of the preferred sources are multiplied by (1 + hysteresis).
std::vector<SourceScore> ApplySourceHysteresis(std::vector<SourceScore> ranked,
                                               const std::vector<int>& preferred,
                                               double hysteresis, int k);

// With options.source_hysteresis > 0 and target.preferred_sources, the choice favours
// the preferred sources (ApplySourceHysteresis); options.stable_source_order sorts the
// chosen ones by view index.
PreparedTarget PrepareTarget(const Scene& scene, const TargetView& target,
                             const RenderOptions& options);

// A method that blends the warped sources pixel by pixel on the CPU (`nearest`, `ulr`):
// Render is PrepareTarget, then Blend into a result of the target's size (black colour,
// zero confidence and coverage before it), then the target depth, the infinity mask and
// the blend's time added.
class PixelBlendMethod : public Method {
 public:
  RenderResult Render(const Scene& scene, const TargetView& target) final;

 protected:
  // Checks the options (fvs::Error when invalid).
  explicit PixelBlendMethod(const RenderOptions& options);
  // Writes result->color, confidence and coverage where some source sees the pixel.
  virtual void Blend(const Scene& scene, const TargetView& target,
                     const PreparedTarget& prepared, RenderResult* result) const = 0;

  RenderOptions options_;
};

}  // namespace fvs
