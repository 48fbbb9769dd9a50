#include "fvs/net/lpips_weights.h"

#include <cstdlib>

#include "fvs/util/error.h"

namespace fvs {
namespace {

// Side after a max pool of the network, or 0 when the pool has no full window.
int PooledSize(const std::string& network, int side) {
  const int window = network == "alex" ? 3 : 2;
  return side < window ? 0 : (side - window) / 2 + 1;
}

// Side of the last tapped layer for an input side, or 0 when some layer has no pixel.
int LastTapSize(const std::string& network, int side) {
  for (const LpipsConv& c : LpipsLayout(network)) {
    if (c.pool_before) side = PooledSize(network, side);
    if (side + 2 * c.padding < c.kernel) return 0;
    side = (side + 2 * c.padding - c.kernel) / c.stride + 1;
  }
  return side;
}

}  // namespace

std::string ResolveLpipsPath(const std::string& flag) {
  if (!flag.empty()) return flag;
  const char* env = std::getenv(kLpipsPathEnv);
  return env ? env : "";
}

std::vector<LpipsConv> LpipsLayout(const std::string& network) {
  Require(network == "alex" || network == "vgg", "LPIPS",
          "network must be alex or vgg, not '" + network + "'");
  if (network == "alex") {
    return {{0, 3, 64, 11, 4, 2, false, true},
            {3, 64, 192, 5, 1, 2, true, true},
            {6, 192, 384, 3, 1, 1, true, true},
            {8, 384, 256, 3, 1, 1, false, true},
            {10, 256, 256, 3, 1, 1, false, true}};
  }
  return {{0, 3, 64, 3, 1, 1, false, false},     {2, 64, 64, 3, 1, 1, false, true},
          {5, 64, 128, 3, 1, 1, true, false},    {7, 128, 128, 3, 1, 1, false, true},
          {10, 128, 256, 3, 1, 1, true, false},  {12, 256, 256, 3, 1, 1, false, false},
          {14, 256, 256, 3, 1, 1, false, true},  {17, 256, 512, 3, 1, 1, true, false},
          {19, 512, 512, 3, 1, 1, false, false}, {21, 512, 512, 3, 1, 1, false, true},
          {24, 512, 512, 3, 1, 1, true, false},  {26, 512, 512, 3, 1, 1, false, false},
          {28, 512, 512, 3, 1, 1, false, true}};
}

std::vector<std::pair<std::string, std::vector<int64_t>>> LpipsExpectedTensors(
    const std::string& network) {
  std::vector<std::pair<std::string, std::vector<int64_t>>> names;
  std::vector<int> tap_channels;
  for (const LpipsConv& c : LpipsLayout(network)) {
    const std::string prefix = "features." + std::to_string(c.index);
    names.push_back({prefix + ".weight", {c.out, c.in, c.kernel, c.kernel}});
    names.push_back({prefix + ".bias", {c.out}});
    if (c.tap) tap_channels.push_back(c.out);
  }
  for (size_t k = 0; k < tap_channels.size(); ++k) {
    names.push_back(
        {"lin" + std::to_string(k) + ".model.1.weight", {1, tap_channels[k], 1, 1}});
  }
  return names;
}

int LpipsMinimumSize(const std::string& network) {
  int side = 1;
  while (LastTapSize(network, side) < 1) ++side;
  return side;
}

}  // namespace fvs
