// What an LPIPS v0.1 weights file (Zhang et al. 2018) holds and where to find one; no
// torch here, so that the evaluation's and the trainer's option code can include it.
// The network itself is net/lpips_net.h.
//
// The file holds, by the official names:
//   features.<i>.weight / .bias   torchvision alexnet().features or vgg16().features
//   lin<k>.model.1.weight         [1, C_k, 1, 1], k = 0..4 (the lpips package's names)
// and the network is recognised from them (features.28 exists only in VGG16).
// doc/evaluation.md shows how to convert the official weights.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace fvs {

// The environment variable naming the weights when no --lpips_path is given.
inline constexpr char kLpipsPathEnv[] = "FVS_LPIPS_PATH";

// The weights file to use: `flag` (--lpips_path) when not empty, else $FVS_LPIPS_PATH,
// else "" (no LPIPS). The flag wins so that one run can override a shell's default.
std::string ResolveLpipsPath(const std::string& flag);

// One conv of a torchvision `features` stack: its index, channels, kernel, stride,
// padding, whether a max pool (3x3 stride 2 for AlexNet, 2x2 for VGG) comes before it,
// and whether an LPIPS layer is tapped after its ReLU.
struct LpipsConv {
  int index, in, out, kernel, stride, padding;
  bool pool_before, tap;
};

// The convs of "alex" or "vgg" in order; throws fvs::Error for another name.
std::vector<LpipsConv> LpipsLayout(const std::string& network);

// Names and shapes a file must hold for "alex" or "vgg": weight and bias of each conv of
// LpipsLayout in order, then lin0..lin4 (tests, docs, error messages).
std::vector<std::pair<std::string, std::vector<int64_t>>> LpipsExpectedTensors(
    const std::string& network);

// The smallest image side for which every tapped layer of the network still has a pixel
// (AlexNet: 31, VGG16: 16); smaller images are padded up to it (LpipsNetImpl::forward).
int LpipsMinimumSize(const std::string& network);

}  // namespace fvs
