// Per-view stereo at the novel view: the proxy's depth refined per pixel the way stereo
// refines depth, not the way a blend does. The depth sweep (tools/headroom/depth_sweep.h)
// scored a depth by the sources' colour variance and failed where every depth agrees
// (flat and dark regions, where silhouettes slid onto the backdrop) and where noise picks
// the depth (winner-take-all per pixel). Here each candidate depth is scored by
// normalised cross-correlation of each seeing source against the pixel's reference source
// (the one with the most ULR weight) over a window, with windows too flat to correlate
// scored neutral; the cost volume is smoothed by semi-global matching (four scanline
// directions, penalties for a step of one candidate and for larger jumps) with a prior
// toward the proxy. A measurement of the headroom runner (tools/headroom/headroom.h).
#pragma once

#include <torch/torch.h>

#include "fvs/train/data.h"

namespace fvs {

struct DepthStereoOptions {
  int steps = 4;               // candidates on each side of the proxy's depth
  double max_relative = 0.03;  // the farthest candidates: depth x (1 -+ this)
  int radius = 3;              // correlation window (2 radius + 1)^2
  // Windows whose luminance standard deviation is below this (in [0,1] units) in the
  // reference or the other source carry no evidence: cost 1, as for no correlation.
  double min_texture = 0.01;
  double prior = 0.02;  // cost per |step| / steps, toward the proxy's depth
  double p1 = 0.05;     // semi-global matching: a step of one candidate
  double p2 = 0.3;      // and any larger jump (>= p1)
  // Plus this times the window's mean absolute luminance difference / 0.1: correlation
  // alone cannot see a shift along a smooth ramp of shading (it only adds an offset).
  double absolute_weight = 0;
  void Check() const;  // throws fvs::Error
};

// Semi-global aggregation of a cost volume float [D,h,w] (finite) along the four
// scanline directions: the sum over directions of L(p,d) = C(p,d) + min(L(q,d),
// L(q,d+-1) + p1, min L(q,.) + p2) - min L(q,.), q the previous pixel on the path.
// Returns float [D,h,w]; its argmin over D is the smoothed choice.
torch::Tensor SemiGlobalAggregate(const torch::Tensor& cost, double p1, double p2);

// The ULR blend of sample `s` of `scene` (full-size target, ULR log-weights computed
// with `settings`) with each covered pixel's depth moved to the candidate depth x (1 + d)
// chosen by the correlation cost and semi-global matching above. Which sources see a
// pixel and their ULR weights stay those of the proxy's depth; pixels seen by fewer than
// two sources keep the proxy's depth. [1,3,h,w] in [0,1]. `chosen`, when given,
// receives the chosen relative change d per pixel [1,1,h,w].
torch::Tensor DepthStereoBlend(const PackedScene& scene, const TrainingSample& s,
                               const SampleWarpOptions& settings,
                               const DepthStereoOptions& options,
                               torch::Tensor* chosen = nullptr);

}  // namespace fvs
