#include "fvs/eval/metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "fvs/util/error.h"

namespace fvs::eval {
namespace {

// The pair of images whose reference values were computed with scikit-image 0.19.3:
//   structural_similarity(a, b, gaussian_weights=True, sigma=1.5,
//                         use_sample_covariance=False, data_range=1.0, channel_axis=-1)
//   peak_signal_noise_ratio(a, b, data_range=1.0)
// with a = 0.5 + 0.4 sin(0.3x + 0.2y + c), b = clip(a + 0.1 cos(0.7x - 0.4y + 2c), 0, 1),
// both rounded to float32, 37x29 pixels, 3 channels.
void MakeReferencePair(Image* a, Image* b) {
  *a = Image(37, 29, 3);
  *b = Image(37, 29, 3);
  for (int y = 0; y < 29; ++y) {
    for (int x = 0; x < 37; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double va = 0.5 + 0.4 * std::sin(0.3 * x + 0.2 * y + c);
        const double vb =
            std::clamp(va + 0.1 * std::cos(0.7 * x - 0.4 * y + 2 * c), 0.0, 1.0);
        a->at(x, y, c) = static_cast<float>(va);
        b->at(x, y, c) = static_cast<float>(vb);
      }
    }
  }
}

TEST(Metrics, MatchScikitImageReference) {
  Image a, b;
  MakeReferencePair(&a, &b);
  EXPECT_NEAR(Ssim(a, b), 0.8792596147245315, 1e-6);
  EXPECT_NEAR(Psnr(a, b), 23.009676714655516, 1e-5);
  EXPECT_NEAR(Ssim(b, a), Ssim(a, b), 1e-12);  // symmetric
}

TEST(Metrics, AnalyticValues) {
  // Constant images: the contrast-structure term is C2 / C2 = 1, luminance is closed
  // form.
  const Image a(20, 20, 3, 0.2f), b(20, 20, 3, 0.6f);
  const double C1 = 1e-4;
  const double expected = (2 * 0.2 * 0.6 + C1) / (0.2 * 0.2 + 0.6 * 0.6 + C1);
  EXPECT_NEAR(Ssim(a, b), expected, 1e-6);
  EXPECT_NEAR(Psnr(a, b), -10 * std::log10(0.16), 1e-5);
  EXPECT_DOUBLE_EQ(Ssim(a, a), 1.0);
  EXPECT_EQ(Psnr(a, a), kMaxPsnr);
}

TEST(Metrics, MaskRestrictsPixels) {
  Image a(20, 20, 1, 0.5f), b(20, 20, 1, 0.5f), mask(20, 20, 1, 0.0f);
  for (int y = 0; y < 20; ++y) {
    for (int x = 10; x < 20; ++x) b.at(x, y) = 0.0f;    // right half wrong
    for (int x = 0; x < 10; ++x) mask.at(x, y) = 1.0f;  // left half counted
  }
  EXPECT_EQ(Psnr(a, b, &mask), kMaxPsnr);
  EXPECT_LT(Psnr(a, b), 10.0);
  Image empty_mask(20, 20, 1, 0.0f);
  EXPECT_THROW(Psnr(a, b, &empty_mask), Error);
}

TEST(Metrics, QuantizationRoundsLikeAPng) {
  Image a(2, 1, 1);
  a.at(0, 0) = 0.5f;           // 127.5 -> 128
  a.at(1, 0) = std::nanf("");  // never leaks
  const Image q = QuantizeTo8Bit(a);
  EXPECT_FLOAT_EQ(q.at(0, 0), 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(q.at(1, 0), 0.0f);
}

TEST(Metrics, BadInputIsAnError) {
  const Image a(20, 20, 3), b(21, 20, 3), tiny(5, 5, 3);
  EXPECT_THROW(Psnr(a, b), Error);
  EXPECT_THROW(Ssim(a, b), Error);
  EXPECT_THROW(Ssim(tiny, tiny), Error);
  EXPECT_THROW(Psnr(Image(), Image()), Error);
}

}  // namespace
}  // namespace fvs::eval
