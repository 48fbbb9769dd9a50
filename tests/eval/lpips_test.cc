// LPIPS from a safetensors file: the AlexNet and VGG16 layouts load from random weights
// written here (the official weights are not shipped: their values are checked by the
// conversion recipe of doc/evaluation.md, not here), the distance behaves as LPIPS must
// (0 for identical images, symmetric, linear in the lin layers), and every problem with
// the file makes LPIPS "not available" with the reason, never a number.
#include "fvs/eval/lpips.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "fvs/util/safetensors.h"
#include "support/test_support.h"

namespace fvs::eval {
namespace {

// Deterministic pseudo-random weights: He-like scale so that activations stay O(1).
std::string WriteRandomLpips(const std::string& path, const std::string& network,
                             float lin_scale = 1.0f, const std::string& skip = "") {
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

Image Pattern(int w, int h, double phase) {
  Image image(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) =
            static_cast<float>(0.5 + 0.45 * std::sin(0.31 * x + 0.17 * y + c + phase));
      }
    }
  }
  return image;
}

TEST(Lpips, BothNetworksLoadAndMeasure) {
  testing::TempDir dir;
  const Image a = Pattern(64, 48, 0.0), b = Pattern(64, 48, 0.7);
  for (const std::string network : {"alex", "vgg"}) {
    std::string why_not, found;
    PerceptualDistance lpips = LoadLpips(
        WriteRandomLpips(dir / (network + ".safetensors"), network), &why_not, &found);
    ASSERT_TRUE(lpips) << why_not;
    EXPECT_TRUE(why_not.empty());
    EXPECT_EQ(found, network);
    EXPECT_DOUBLE_EQ(lpips(a, a), 0.0) << network;
    const double ab = lpips(a, b), ba = lpips(b, a);
    EXPECT_TRUE(std::isfinite(ab)) << network;
    EXPECT_GT(ab, 0.0) << network;
    EXPECT_NEAR(ab, ba, 1e-6 * std::max(1.0, ab)) << network;
    EXPECT_GT(lpips(a, Pattern(64, 48, 2.0)), 0.0) << network;

    // The lin layers weight the squared feature differences linearly.
    PerceptualDistance doubled = LoadLpips(
        WriteRandomLpips(dir / (network + "_x2.safetensors"), network, 2.0f), &why_not);
    ASSERT_TRUE(doubled) << why_not;
    EXPECT_NEAR(doubled(a, b), 2 * ab, 1e-5 * ab) << network;
  }
}

TEST(Lpips, BadFilesAreNotAvailableWithTheReason) {
  testing::TempDir dir;
  std::string why_not;
  EXPECT_FALSE(LoadLpips("", &why_not));
  EXPECT_EQ(why_not, "LPIPS: not available (no --lpips_path given)");
  EXPECT_FALSE(LoadLpips(dir / "missing.safetensors", &why_not));
  EXPECT_NE(why_not.find("missing.safetensors: no such file"), std::string::npos)
      << why_not;
  EXPECT_FALSE(LoadLpips(
      WriteRandomLpips(dir / "no_lin4.safetensors", "alex", 1.0f, "lin4.model.1.weight"),
      &why_not));
  EXPECT_NE(why_not.find("lin4.model.1.weight missing"), std::string::npos) << why_not;
  testing::WriteTextFile(dir / "garbage.safetensors", "not a safetensors file");
  EXPECT_FALSE(LoadLpips(dir / "garbage.safetensors", &why_not));
  EXPECT_NE(why_not.find("LPIPS: not available"), std::string::npos) << why_not;
}

}  // namespace
}  // namespace fvs::eval
