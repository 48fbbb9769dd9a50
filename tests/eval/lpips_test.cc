// LPIPS from a safetensors file: the official weights (../shared/weights, never in the
// repository; skipped, visibly, where absent) reproduce the lpips package's own example
// distances; the AlexNet and VGG16 layouts load from random weights written here, the
// distance behaves as LPIPS must (0 for identical images, symmetric, linear in the lin
// layers), and every problem with the file makes LPIPS "not available" with the reason,
// never a number.
#include "fvs/eval/lpips.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "colmap_ext/image_io.h"
#include "net/lpips_fixture.h"
#include "support/test_support.h"

namespace fvs::eval {
namespace {

using testing::WriteRandomLpips;

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

// The lpips package's test_network.py prints "Distances: (0.722, 0.138)" for these
// images with lpips.LPIPS(net='alex'), v0.1 (/work/shared/weights/README.md).
TEST(Lpips, OfficialExampleDistancesWithTheRealWeights) {
  std::string why_skip;
  const std::string weights =
      testing::SharedFile("weights/lpips_alex.safetensors", &why_skip);
  if (weights.empty()) GTEST_SKIP() << why_skip;
  const std::string images = testing::SharedDir() + "/weights/lpips_test_images/";
  std::string why_not, network;
  const PerceptualDistance lpips = LoadLpips(weights, &why_not, &network);
  ASSERT_TRUE(lpips) << why_not;
  EXPECT_EQ(network, "alex");
  const Image ref = colmap::ReadImage(images + "ex_ref.png");
  const double d0 = lpips(ref, colmap::ReadImage(images + "ex_p0.png"));
  const double d1 = lpips(ref, colmap::ReadImage(images + "ex_p1.png"));
  std::printf("LPIPS alex, official example: ref-p0 %.4f (0.722), ref-p1 %.4f (0.138)\n",
              d0, d1);
  EXPECT_NEAR(d0, 0.722, 0.002);
  EXPECT_NEAR(d1, 0.138, 0.002);
  EXPECT_EQ(lpips(ref, ref), 0.0);
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
  EXPECT_EQ(why_not,
            "LPIPS: not available (no --lpips_path given, FVS_LPIPS_PATH not set)");
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
