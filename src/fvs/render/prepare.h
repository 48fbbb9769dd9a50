// The geometric front end every method shares: target depth from the proxy mesh, the
// top-K sources by overlap, and one warping map per selected source (same target depth
// for all).
#pragma once

#include <vector>

#include "fvs/render/method.h"
#include "fvs/geometry/warp.h"

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

}  // namespace fvs
