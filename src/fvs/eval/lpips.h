// LPIPS v0.1 (Zhang et al. 2018), the learned perceptual distance of the paper's tables,
// for fvs::Image pairs: a thin wrapper over the LibTorch network of net/lpips_net.h,
// loaded from a user-given safetensors file (--lpips_path or $FVS_LPIPS_PATH,
// ResolveLpipsPath; the layout is net/lpips_weights.h, the conversion of the official
// weights doc/evaluation.md). Without the file LPIPS is "not available" in every output:
// never estimated, never replaced by something else. No torch in this header.
#pragma once

#include <string>

#include "fvs/eval/evaluate.h"
#include "fvs/net/lpips_weights.h"

namespace fvs::eval {

// Loads the weights; on any problem returns an empty function and sets *why_not to one
// line naming the file and the reason (the evaluation goes on without LPIPS). On success
// *why_not is empty and *network is "alex" or "vgg". The function may be called from
// several threads (they take turns).
PerceptualDistance LoadLpips(const std::string& path, std::string* why_not,
                             std::string* network = nullptr);

}  // namespace fvs::eval
