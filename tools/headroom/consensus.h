// Colour consensus across the warped sources: a blend that needs no photo and no
// training, and the prior the aggregate blender can start from (ModelConfig
// consensus_tau). Where the proxy mesh is a few pixels off, each source lands its colour
// somewhere else and a weighted average doubles the image; the sources that agree with
// the others over a small window are the ones to trust there.
//
// One reweighting (an iteratively reweighted robust mean): with the blend B of the
// current weights, source k's squared distance to it, averaged over the channels and a
// (2r+1)^2 window of the pixels k sees, is d_k; its log-weight drops by d_k / (2 tau^2).
// `iterations` such steps, each from the blend of the previous one.
// Only torch code includes this header.
#pragma once

#include <torch/torch.h>

namespace fvs {

struct ConsensusOptions {
  double tau = 0;      // colour scale on [0, 1] colours; 0 = off
  int radius = 2;      // window (2r+1)^2
  int iterations = 1;  // reweightings
};

// Blend weights [K,1,H,W] among the seeing sources: the softmax of `log_weights`
// [K,1,H,W] over the sources that see each pixel (`seen` [K,1,H,W], 1 or 0), 0 for the
// others and everywhere no source sees. Masked before the softmax, so the seeing sources
// keep their weight however large a hidden source's log-weight is.
torch::Tensor SeenWeights(const torch::Tensor& log_weights, const torch::Tensor& seen);
// The blend [1,C,H,W] of colours [K,C,H,W] with SeenWeights (0 where no source sees).
torch::Tensor BlendSeen(const torch::Tensor& colours, const torch::Tensor& seen,
                        const torch::Tensor& log_weights);

// Box mean over a (2r+1)^2 window, the same size out (edges replicated); r = 0: x.
torch::Tensor BoxMean(const torch::Tensor& x, int radius);
// The same, but near the border the mean of the window's pixels inside the image (no
// padding counted); r = 0: x.
torch::Tensor BoxMeanInImage(const torch::Tensor& x, int radius);

// The log-weight terms [K,1,H,W] (<= 0, finite) to add to `log_weights` [K,1,H,W].
// colours [K,3,H,W] on [0, 1]; seen [K,1,H,W] (1 where the source sees the pixel); the
// blend is over the seeing sources, weights softmax(log_weights). Zeros when tau is 0.
torch::Tensor ConsensusLogWeights(const torch::Tensor& colours, const torch::Tensor& seen,
                                  const torch::Tensor& log_weights,
                                  const ConsensusOptions& options);

struct AlignOptions {
  int search = 0;         // shifts up to +-search target pixels in x and y; 0 = off
  int window = 3;         // matching window (2w+1)^2
  double penalty = 1e-4;  // added cost per squared pixel of shift (prefers no shift)
  int iterations = 1;     // align, blend again, align again
};

// Each warped source moved, per target pixel, by the integer shift within +-search that
// best matches the current blend over a window (a local, per-source correction of where
// the proxy put it; Floating Textures, Eisemann et al. 2008, align the sources by optical
// flow for the same reason). colours [K,3,H,W] and seen [K,1,H,W] are replaced by the
// shifted ones; the blend is softmax(log_weights) over the seeing sources.
void AlignToBlend(torch::Tensor* colours, torch::Tensor* seen,
                  const torch::Tensor& log_weights, const AlignOptions& options);

}  // namespace fvs
