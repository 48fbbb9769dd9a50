// Area resampling and the box blur: a constant image stays constant, the sum of an
// image is kept by a 2x reduction, the blur's border averages only the pixels inside, and
// bad arguments are refused.
#include "fvs/util/image_resize.h"

#include <gtest/gtest.h>

#include "fvs/util/error.h"

namespace fvs {
namespace {

Image Ramp(int width, int height, int channels) {
  Image image(width, height, channels);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = static_cast<float>(i % 17);
  return image;
}

TEST(ResizeAreaTest, ConstantStaysAndAHalvingAveragesBlocks) {
  const Image grey(9, 7, 3, 0.25f);
  for (float v : ResizeArea(grey, 4, 3).data) EXPECT_FLOAT_EQ(v, 0.25f);
  const Image ramp = Ramp(8, 6, 1);
  const Image half = ResizeArea(ramp, 4, 3);
  EXPECT_NEAR(half.at(1, 1, 0),
              (ramp.at(2, 2, 0) + ramp.at(3, 2, 0) + ramp.at(2, 3, 0) + ramp.at(3, 3, 0)) / 4,
              1e-5);
  EXPECT_THROW(ResizeArea(ramp, 0, 3), Error);
}

TEST(BoxBlurTest, WindowMeansInsideTheImage) {
  const Image ramp = Ramp(6, 5, 2);
  EXPECT_EQ(BoxBlur(ramp, 0).data, ramp.data);
  const Image blurred = BoxBlur(ramp, 1);
  // A corner: the four pixels inside its window.
  EXPECT_NEAR(blurred.at(0, 0, 1),
              (ramp.at(0, 0, 1) + ramp.at(1, 0, 1) + ramp.at(0, 1, 1) + ramp.at(1, 1, 1)) / 4,
              1e-5);
  // Inside: all nine.
  float sum = 0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) sum += ramp.at(3 + dx, 2 + dy, 0);
  }
  EXPECT_NEAR(blurred.at(3, 2, 0), sum / 9, 1e-5);
  // A radius larger than the image: every pixel is the image's mean.
  const Image wide = BoxBlur(Image(3, 2, 1, 0.5f), 10);
  for (float v : wide.data) EXPECT_FLOAT_EQ(v, 0.5f);
  EXPECT_THROW(BoxBlur(ramp, -1), Error);
}

}  // namespace
}  // namespace fvs
