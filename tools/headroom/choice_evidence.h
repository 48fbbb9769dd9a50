// Per-source evidence for the choice among warped sources, and a tiny per-pixel model
// over it: issue 16's question whether cheap measurements the warp already makes tell
// which source is right at a target pixel, where the warped colours, their agreement and
// the ULR terms (fvs_agg's inputs) do not. A measurement tool of the headroom runner
// (tools/headroom/headroom.h): the model is fitted on training scenes and judged as a
// blend on other views; nothing renders with it.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/train/data.h"

namespace fvs {

// The evidence channels of SourceEvidence, in order.
enum EvidenceChannel {
  kEvidenceUlrLogWeight = 0,  // ULR log-weight less the best seeing source's, / 4
  kEvidenceOcclusion,         // 4 log(source depth at the sample / the point's depth)
  kEvidenceOcclusionAbs,      // its magnitude
  kEvidenceFootprint,         // log of source pixels per target pixel (Jacobian)
  kEvidenceFootprintCoarse,   // its positive part (the source sees the surface coarser)
  kEvidenceBorder,            // distance to the source image's border / 16 px, <= 1
  kEvidenceSharpness,       // log gradient energy in source space, less the sources' mean
  kEvidenceBlendDistance5,  // 10 x colour distance to the ULR blend, 5x5 mean
  kEvidenceBlendDistance,   // the same at the pixel
  kEvidenceSeenShare,       // share of the K sources that see the pixel
  kEvidenceSurface,         // 1 where the target pixel has a surface (not infinity)
  // Per source, constant over the view (what the best global weighting of the headroom
  // tool can key on): the share of the view the source sees, its mean sharpness less the
  // sources' mean, and 10 x its mean colour distance to the ULR blend.
  kEvidenceCoverage,
  kEvidenceGlobalSharpness,
  kEvidenceGlobalBlendDistance,
  kNumEvidence
};

// A short name of each channel ("occlusion", ...), for reports.
const char* EvidenceChannelName(int channel);

// float [K, kNumEvidence, h, w] for sample `s` of `scene` (full-size sources, the ULR
// log-weights computed) and its warped colours [K,3,h,w] in [0,1]. Every channel is
// finite and bounded; channels of a source that does not see a pixel are 0 there.
torch::Tensor SourceEvidence(const PackedScene& scene, const TrainingSample& s,
                             const torch::Tensor& colours);

// Blend log-weights [K,1,h,w] = ULR log-weights + g(evidence of the source), one g shared
// by all sources: linear (hidden 0) or one hidden ReLU layer. g starts at zero, so an
// unfitted model blends exactly as `ulr` does. `local_only` hides the per-view channels
// (kEvidenceCoverage and after): a handful of views gives them a handful of values each,
// too few to fit without learning the views.
struct ChoiceModelImpl : torch::nn::Module {
  explicit ChoiceModelImpl(int hidden, bool local_only = false);
  torch::Tensor forward(const torch::Tensor& evidence,
                        const torch::Tensor& ulr_log_weights);
  int hidden;
  torch::Tensor channel_mask;  // [kNumEvidence], 0 for hidden channels
  torch::nn::Linear first{nullptr}, second{nullptr};
};
TORCH_MODULE(ChoiceModel);

struct ChoiceFitOptions {
  int hidden = 0;
  bool local_only = false;     // ChoiceModelImpl
  bool squared_error = false;  // fit the squared error (PSNR's) instead of L1
  int steps = 400;
  double learning_rate = 0.02;
  int pixels_per_view = 8192;  // random covered pixels of each target view
  uint64_t seed = 1;
};

struct ChoiceFit {
  ChoiceModel model{nullptr};
  int64_t pixels = 0;  // fitted on (0: no target view had K sources)
  double start_error = 0,
         final_error = 0;  // the fitted error on those pixels (start: `ulr`'s)
};

// Fit settings from "HIDDEN:LOSS:CHANNELS,..." (LOSS l1 or l2, CHANNELS all or local);
// "" gives none. Throws fvs::Error naming the spec that does not parse.
std::vector<ChoiceFitOptions> ParseChoiceSpecs(const std::string& specs);
// "choice_h16_l2_local" and the like: the headroom row of a fit.
std::string ChoiceSpecName(const ChoiceFitOptions& fit);

// Fits a ChoiceModel to the target views of `scenes` (IsTargetView with
// `holdout_targets`, those with K sources by overlap): the L1 error of its blend against
// the photo on random covered pixels, full batch, Adam. Prints one line of progress per
// 100 steps to stderr unless quiet.
ChoiceFit FitChoiceModel(const std::vector<PackedScene>& scenes, int num_sources,
                         const SampleWarpOptions& warp, bool holdout_targets,
                         const ChoiceFitOptions& options, bool quiet = false);

}  // namespace fvs
