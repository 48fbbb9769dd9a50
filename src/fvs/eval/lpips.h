// LPIPS v0.1 (Zhang et al. 2018), the learned perceptual distance of the paper's tables,
// computed by our LibTorch code from a user-given safetensors file; doc/evaluation.md
// shows how to convert the official weights (the lpips package's lin layers plus the
// torchvision AlexNet or VGG16 backbone it uses). Without the file LPIPS is "not
// available" in every output: never estimated, never replaced by something else.
//
// The file holds, by the official names:
//   features.<i>.weight / .bias   torchvision alexnet().features or vgg16().features
//   convs lin<k>.model.1.weight         [1, C_k, 1, 1], k = 0..4 (the lpips package's
//   names)
// and the network is recognised from them (features.28 exists only in VGG16).
// The distance: inputs in [0,1] -> [-1,1] -> (x - shift) / scale; at relu1..relu5
// (AlexNet) or relu1_2, relu2_2, relu3_3, relu4_3, relu5_3 (VGG16) the features are
// unit-normalised over channels (eps 1e-10), squared differences weighted by lin<k>,
// averaged over the image, summed over the five layers. No torch in this header.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "fvs/eval/evaluate.h"

namespace fvs::eval {

// Loads the weights; on any problem returns an empty function and sets *why_not to one
// line naming the file and the reason (the evaluation goes on without LPIPS). On success
// *why_not is empty and *network is "alex" or "vgg".
PerceptualDistance LoadLpips(const std::string& path, std::string* why_not,
                             std::string* network = nullptr);

// Names and shapes a file must hold for "alex" or "vgg" (tests, docs, error messages).
std::vector<std::pair<std::string, std::vector<int64_t>>> LpipsExpectedTensors(
    const std::string& network);

}  // namespace fvs::eval
