// Random LPIPS weights under the official names, for the tests of the metric, the loss
// and the commands where the real weights (../shared/weights) are not needed or absent.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fvs/net/lpips_weights.h"
#include "fvs/util/safetensors.h"

namespace fvs::testing {

// Writes deterministic pseudo-random weights of "alex" or "vgg" to `path` and returns it:
// He-like scale so that activations stay O(1); lin weights in [0, 0.1 lin_scale) (the
// official ones are >= 0). `skip` names a tensor to leave out (bad-file tests).
inline std::string WriteRandomLpips(const std::string& path, const std::string& network,
                                    float lin_scale = 1.0f,
                                    const std::string& skip = "") {
  uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<float>((state >> 40) & 0xFFFFFF) / 16777216.0f;  // [0, 1)
  };
  SafeTensorsFile file;
  for (const auto& [name, shape] : LpipsExpectedTensors(network)) {
    if (name == skip) continue;
    int64_t count = 1, fan_in = 1;
    for (size_t i = 0; i < shape.size(); ++i) {
      count *= shape[i];
      if (i > 0) fan_in *= shape[i];
    }
    std::vector<float> values(count);
    const bool lin = name.rfind("lin", 0) == 0;
    const float scale = std::sqrt(6.0f / std::max<int64_t>(1, fan_in));
    for (float& v : values) {
      v = lin ? lin_scale * 0.1f * uniform() : (2 * uniform() - 1) * scale;
    }
    file.Add(SafeTensor::FromFloats(name, shape, values.data()));
  }
  WriteSafeTensors(path, file);
  return path;
}

}  // namespace fvs::testing
