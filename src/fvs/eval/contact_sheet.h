// Contact sheets: every evaluated view as a row, the rendered image beside the photo,
// labelled with its numbers (PSNR, SSIM, LPIPS, time, K used) or its error.
#pragma once

#include <string>
#include <vector>

#include "fvs/eval/evaluate.h"

namespace fvs::eval {

// One row per result (one configuration), in order; the thumbnails are matched by target
// name (a failed view has none: its row is the error in red).
Image MakeContactSheet(const std::string& title, const std::vector<ViewResult>& results,
                       const std::vector<ViewThumbnails>& thumbnails);

// Stacks sheets (e.g. of shards) top to bottom, left-aligned on white.
Image StackVertically(const std::vector<Image>& images);

}  // namespace fvs::eval
