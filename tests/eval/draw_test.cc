// The drawing the contact sheets and plots rely on: glyphs where the font says, lines and
// markers in their colour, resampling that keeps a constant image constant, and a plot
// that holds one curve colour per method.
#include "fvs/eval/draw.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fvs/eval/contact_sheet.h"
#include "fvs/eval/plot.h"
#include "fvs/util/error.h"

namespace fvs::eval {
namespace {

int CountDark(const Image& image, int x0, int y0, int w, int h) {
  int n = 0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) n += image.at(x, y, 0) < 0.5f ? 1 : 0;
  }
  return n;
}

bool HasColour(const Image& image, const Rgb& c) {
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (std::abs(image.at(x, y, 0) - c.r) < 0.02 &&
          std::abs(image.at(x, y, 1) - c.g) < 0.02 &&
          std::abs(image.at(x, y, 2) - c.b) < 0.02) {
        return true;
      }
    }
  }
  return false;
}

TEST(Draw, TextUsesTheFontAndScales) {
  Image image(60, 30, 3, 1.0f);
  DrawText(&image, 2, 2, "I -", {0, 0, 0});
  EXPECT_EQ(TextWidth("I -"), 18);
  const int i_pixels = CountDark(image, 2, 2, 6, 10);
  EXPECT_GT(i_pixels, 6);                         // the stem and serifs of 'I'
  EXPECT_EQ(CountDark(image, 8, 2, 6, 10), 0);    // the space
  EXPECT_GT(CountDark(image, 14, 2, 6, 10), 2);   // '-'
  EXPECT_EQ(CountDark(image, 0, 14, 60, 16), 0);  // nothing below the line
  Image big(60, 30, 3, 1.0f);
  DrawText(&big, 2, 2, "I", {0, 0, 0}, 2);
  EXPECT_EQ(CountDark(big, 0, 0, 60, 30), 4 * i_pixels);
  Image vertical(30, 60, 3, 1.0f);
  DrawTextVertical(&vertical, 2, 2, "I", {0, 0, 0});
  EXPECT_EQ(CountDark(vertical, 0, 0, 30, 60), i_pixels);
}

TEST(Draw, LinesMarkersAndResize) {
  Image image(40, 40, 3, 1.0f);
  DrawLine(&image, 5, 20, 35, 20, {1, 0, 0}, 2.0);
  EXPECT_NEAR(image.at(20, 19, 1), 0.0f, 1e-6);  // covered: red
  EXPECT_NEAR(image.at(20, 30, 1), 1.0f, 1e-6);  // far away: white
  DrawMarker(&image, 10.5, 10.5, Marker::kSquare, 4, {0, 0, 1});
  EXPECT_NEAR(image.at(10, 10, 0), 0.0f, 1e-6);
  DrawLine(&image, NAN, 0, 5, 5, {0, 0, 0});  // ignored, no crash
  Image flat(64, 48, 3, 0.25f);
  const Image small = ResizeImage(flat, 10, 7);
  ASSERT_EQ(small.width, 10);
  ASSERT_EQ(small.height, 7);
  for (float v : small.data) EXPECT_NEAR(v, 0.25f, 1e-6);
}

TEST(Plot, NiceTicksAndOneColourPerMethod) {
  const std::vector<double> ticks = NiceTicks(17.3, 26.1, 5);
  ASSERT_GE(ticks.size(), 2u);
  EXPECT_DOUBLE_EQ(ticks.front(), 18);
  EXPECT_DOUBLE_EQ(ticks[1] - ticks[0], 2);
  std::vector<ConfigSummary> summary(3);
  summary[0].config.method = "nearest";
  summary[0].psnr = 18;
  summary[0].seconds = 0.05;
  summary[1].config.method = "ulr";
  summary[1].config.num_sources = 2;
  summary[1].psnr = 22;
  summary[1].seconds = 0.2;
  summary[1].pareto = true;
  summary[2].config.method = "ulr";
  summary[2].config.num_sources = 4;
  summary[2].psnr = 24;
  summary[2].seconds = 0.4;
  const Image plot = PlotErrorAgainstTime(summary, {});
  EXPECT_EQ(plot.width, 960);
  EXPECT_TRUE(HasColour(plot, {0.0f, 0.45f, 0.70f}));  // first method
  EXPECT_TRUE(HasColour(plot, {0.90f, 0.62f, 0.0f}));  // second method
  std::vector<ConfigSummary> none(1);
  EXPECT_THROW(PlotErrorAgainstTime(none, {}), Error);
}

TEST(ContactSheet, RowsForEveryViewAndRedErrors) {
  ViewResult ok, bad;
  ok.target = "a.png";
  ok.psnr = 30;
  ok.ssim = 0.9;
  ok.seconds = 0.1;
  bad.target = "b.png";
  bad.error = "not a registered image of the model";
  ViewThumbnails t{"a.png", Image(40, 30, 3, 0.0f), Image(40, 30, 3, 0.5f)};
  const Image sheet = MakeContactSheet("title", {ok, bad}, {t});
  EXPECT_GE(sheet.width, 2 * 40);
  EXPECT_GT(sheet.height, 30 + 4 * kGlyphHeight);
  EXPECT_TRUE(HasColour(sheet, {0.75f, 0.1f, 0.1f}));  // the error line
  EXPECT_TRUE(HasColour(sheet, {0.5f, 0.5f, 0.5f}));   // the photo tile
  const Image stacked = StackVertically({sheet, sheet});
  EXPECT_EQ(stacked.height, 2 * sheet.height);
}

}  // namespace
}  // namespace fvs::eval
