// A photo-free blend that corrects the proxy's depth per pixel: where the mesh is a few
// per cent off, the sources' warped colours disagree (the "doubled" look of `ulr`); a
// small sweep of depths around the proxy's, scored by how well the seeing sources agree
// over a window, moves each pixel to the depth where they agree. A measurement of the
// headroom runner (tools/headroom/headroom.h), like the other photo-free blends there: it
// tells whether depth refinement at the novel view is worth building into the renderer.
#pragma once

#include <torch/torch.h>

#include "fvs/train/data.h"

namespace fvs {

struct DepthSweepOptions {
  int steps = 3;               // candidates on each side of the proxy's depth
  double max_relative = 0.03;  // the farthest candidates: depth x (1 -+ this)
  int radius = 2;              // agreement window (2 radius + 1)^2
  // Added to a candidate's cost per |step| / steps (in colour variance units), so that
  // where the sources agree about as well anyway the proxy's depth stays.
  double prior = 1e-4;
  // And a candidate's cost is multiplied by 1 + relative_prior |step| / steps: a move
  // must cut the disagreement by that share, not merely tie (flat and dark regions, where
  // all depths agree about as well, keep the proxy's).
  double relative_prior = 0;
  void Check() const;  // throws fvs::Error
};

// The ULR blend of sample `s` of `scene` (full-size target, ULR log-weights computed
// with `settings`) with each covered pixel's depth moved to the candidate depth x (1 + d)
// whose ULR-weighted colour variance among the seeing sources, averaged over the window,
// is lowest. Which sources see a pixel and their ULR weights stay those of the proxy's
// depth; pixels seen by fewer than two sources keep the proxy's depth. [1,3,h,w] in
// [0,1]. `chosen`, when given, receives the chosen relative change d per pixel [1,1,h,w].
torch::Tensor DepthSweepBlend(const PackedScene& scene, const TrainingSample& s,
                              const SampleWarpOptions& settings,
                              const DepthSweepOptions& options,
                              torch::Tensor* chosen = nullptr);

// What the sweep and the stereo (tools/headroom/depth_stereo.h) share. Throws fvs::Error
// unless `s` is a full-size sample of `scene` with ULR log-weights.
void CheckRefinableSample(const PackedScene& scene, const TrainingSample& s);
// The grid [K,h,w,2] of the sample's sources at its target's proxy depth x (1 + change)
// (change 0: the sample's own grid); checks the sample as above.
torch::Tensor GridAtScaledDepth(const PackedScene& scene, const TrainingSample& s,
                                const SampleWarpOptions& settings, double change);
// The pixels a refinement may move [1,1,h,w] (bool): a surface seen by two sources or
// more.
torch::Tensor Refinable(const TrainingSample& s);

}  // namespace fvs
