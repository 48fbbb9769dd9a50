// Push-pull hole filling: covered pixels untouched, holes in a constant image get the
// constant, holes take their colour from nearby covered pixels rather than far ones, and
// nothing covered / everything covered / NaN colours are handled.
#include "fvs/util/hole_filling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fvs/util/error.h"

namespace fvs {
namespace {

Image Coverage(int w, int h, float value) { return Image(w, h, 1, value); }

TEST(FillHolesTest, CoveredPixelsStayAndAConstantFillsItsHoles) {
  Image color(37, 23, 3, 0.0f);
  Image coverage = Coverage(37, 23, 1.0f);
  for (size_t i = 0; i < 37 * 23; ++i) {
    color.data[3 * i] = 0.25f;
    color.data[3 * i + 1] = 0.5f;
    color.data[3 * i + 2] = 0.75f;
  }
  const Image before = color;
  // Holes: a block, the border column and scattered pixels, set to black.
  for (int y = 0; y < 23; ++y) {
    for (int x = 0; x < 37; ++x) {
      if ((x >= 10 && x < 20 && y >= 5 && y < 15) || x == 36 ||
          (x * 7 + y * 3) % 11 == 0) {
        coverage.at(x, y) = 0;
        for (int c = 0; c < 3; ++c) color.at(x, y, c) = 0;
      }
    }
  }
  FillHoles(coverage, nullptr, &color);
  for (size_t i = 0; i < color.data.size(); ++i) {
    EXPECT_NEAR(color.data[i], before.data[i], 1e-6) << i;
  }
}

TEST(FillHolesTest, HolesTakeTheColourOfTheirNeighbourhood) {
  // Left half red, right half blue, a hole in each half and a covered strip between.
  const int w = 64, h = 32;
  Image color(w, h, 3, 0.0f);
  Image coverage = Coverage(w, h, 1.0f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) color.at(x, y, x < w / 2 ? 0 : 2) = 1.0f;
  }
  const Image original = color;
  for (int y = 10; y < 20; ++y) {
    for (int x : {4, 5, 6, 7, 56, 57, 58, 59}) {
      coverage.at(x, y) = 0;
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = 0.5f;
    }
  }
  FillHoles(coverage, nullptr, &color);
  EXPECT_GT(color.at(5, 15, 0), 0.9f);
  EXPECT_LT(color.at(5, 15, 2), 0.1f);
  EXPECT_GT(color.at(58, 15, 2), 0.9f);
  EXPECT_LT(color.at(58, 15, 0), 0.1f);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (coverage.at(x, y) > 0) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(color.at(x, y, c), original.at(x, y, c));
      }
    }
  }
}

// A bright object (surface) in front of a dark backdrop (no surface): a backdrop hole
// beside the object takes the backdrop's colour, an object hole the object's.
TEST(FillHolesTest, BackdropHolesFillFromTheBackdrop) {
  const int w = 48, h = 32;
  Image color(w, h, 3, 0.05f), depth(w, h, 1, 0.0f);
  Image coverage = Coverage(w, h, 1.0f);
  for (int y = 8; y < 24; ++y) {
    for (int x = 8; x < 24; ++x) {
      depth.at(x, y) = 2.0f;
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = 0.95f;
    }
  }
  for (int y = 10; y < 22; ++y) {
    for (int x : {24, 25, 26, 27, 28, 12, 13}) {  // backdrop hole touching the object,
      coverage.at(x, y) = 0;                      // and a hole inside the object
      for (int c = 0; c < 3; ++c) color.at(x, y, c) = 0.5f;
    }
  }
  Image plain = color;
  FillHoles(coverage, &depth, &color);
  FillHoles(coverage, nullptr, &plain);
  for (int y = 10; y < 22; ++y) {
    EXPECT_NEAR(color.at(24, y, 0), 0.05f, 1e-5) << y;
    EXPECT_GT(color.at(12, y, 0), 0.9f) << y;
  }
  // Without the depth the object bleeds into the backdrop.
  EXPECT_GT(plain.at(24, 16, 0), 0.2f);
  const Image small_depth(w / 2, h, 1);
  EXPECT_THROW(FillHoles(coverage, &small_depth, &color), Error);
}

TEST(FillHolesTest, NothingOrEverythingCoveredAndNonFiniteColours) {
  Image black(9, 7, 3, 0.0f);
  FillHoles(Coverage(9, 7, 0.0f), nullptr, &black);  // nothing to pull from: left black
  for (float v : black.data) EXPECT_EQ(v, 0.0f);

  Image full(9, 7, 3, 0.3f);
  FillHoles(Coverage(9, 7, 1.0f), nullptr, &full);
  for (float v : full.data) EXPECT_EQ(v, 0.3f);

  // A NaN colour counts as a hole and leaves no NaN behind; a NaN coverage likewise.
  Image color(9, 7, 3, 0.6f);
  Image coverage = Coverage(9, 7, 1.0f);
  color.at(4, 3, 1) = std::numeric_limits<float>::quiet_NaN();
  coverage.at(0, 0) = std::numeric_limits<float>::quiet_NaN();
  FillHoles(coverage, nullptr, &color);
  for (float v : color.data) EXPECT_NEAR(v, 0.6f, 1e-6);

  // One pixel wide and one pixel high images.
  Image column(1, 5, 3, 0.0f);
  Image column_coverage = Coverage(1, 5, 0.0f);
  column_coverage.at(0, 4) = 1;
  for (int c = 0; c < 3; ++c) column.at(0, 4, c) = 0.8f;
  FillHoles(column_coverage, nullptr, &column);
  for (float v : column.data) EXPECT_NEAR(v, 0.8f, 1e-6);

  Image wrong(4, 4, 3);
  EXPECT_THROW(FillHoles(Coverage(5, 4, 1.0f), nullptr, &wrong), Error);
}

}  // namespace
}  // namespace fvs
