// Headroom of a blender with today's geometry, on packed validation scenes: what the
// `ulr` blend renders, what a per-pixel oracle renders (each pixel takes the warped
// source colour closest to the photo, among the K sources that see it), and the best
// single global weighting of the sources per view (K non-negative weights for the whole
// image, blended among the sources that see each pixel; fitted to the photo by Adam on
// the mean squared error). Both oracles see the photo, so they bound what any blender of
// these warps can reach: the per-pixel one shows the gain of a sharp per-pixel choice
// (occlusion, misalignment), the global one how much a better choice of sources alone
// gives. The per-8x8-block oracle (one source per block, the one closest to the photo
// over the block) is a choice that cannot follow the noise pixel by pixel: the per-pixel
// oracle also wins by picking, among equally right sources, the one whose noise lands
// nearest the photo, which no blender can predict. The colour oracle gives the `ulr`
// blend one gain and offset per channel fitted to the photo: the part of the error that
// is a global colour or exposure difference. Beside the oracles, blends that see no
// photo (consensus.h): the ULR weights cut where a source disagrees with the blend
// (consensus_*), the sources shifted locally onto the blend before it (align_*), the
// proxy's depth refined per pixel (sweep_*, tools/headroom/depth_sweep.h; stereo_*,
// tools/headroom/depth_stereo.h), exposure matching (exposure_*) and fitted choices
// (choice_*). Pixels no source sees are filled as the renderer fills them, the same for
// all.
#pragma once

#include <torch/torch.h>

#include <functional>
#include <string>
#include <vector>

#include "fvs/train/data.h"
#include "tools/headroom/choice_evidence.h"

namespace fvs {

struct HeadroomRow {
  std::string scene;
  std::string method;  // ulr | oracle_pixel | oracle_global | oracle_patch8 |
                       // oracle_colour | consensus_<settings> | align_<settings> |
                       // sweep_<settings> | stereo_<settings> | exposure_* | choice_*
  int views = 0;
  double psnr = 0, ssim = 0;
  double lpips = -1;  // -1: no LPIPS function given
};

// Distance of two [1,3,H,W] images in [0,1] (LPIPS); empty = not measured.
using ImageDistance = std::function<double(const torch::Tensor&, const torch::Tensor&)>;

// A blend of fitted per-pixel choice models (tools/headroom/choice_evidence.h), a row
// each.
struct NamedChoiceModel {
  std::string name;
  ChoiceModel model;
};

// The validation views of Trainer::Validate (ValidationTargets with `holdout_targets`,
// top-K sources by overlap, full packed size), one row per scene and method, then the
// means over all views (scene "all"). `methods`: comma-separated prefixes of the method
// names to measure (e.g. "ulr,stereo"); empty = all. Throws fvs::Error when it selects
// none.
std::vector<HeadroomRow> MeasureHeadroom(const std::vector<PackedScene>& scenes,
                                         int num_sources, int views_per_scene,
                                         const SampleWarpOptions& warp,
                                         const ImageDistance& lpips,
                                         bool holdout_targets = false,
                                         const std::vector<NamedChoiceModel>& choice = {},
                                         const std::string& methods = "");

// Writes the rows as CSV (scene,method,views,psnr,ssim,lpips), atomically.
void WriteHeadroomCsv(const std::string& path, const std::vector<HeadroomRow>& rows);

}  // namespace fvs
