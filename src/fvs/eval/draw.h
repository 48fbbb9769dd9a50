// Just enough 2D drawing on fvs::Image (RGB in [0, 1]) for the evaluation's contact
// sheets and plots, which have no plotting library to lean on: rectangles, thick
// anti-aliased lines, markers, resampling and text in a fixed 6x10 bitmap font (the X11
// misc-fixed "6x10", public domain, ASCII 32-126; other bytes draw as '?').
#pragma once

#include <string>

#include "fvs/util/image.h"

namespace fvs::eval {

struct Rgb {
  float r = 0, g = 0, b = 0;
};

constexpr int kGlyphWidth = 6;
constexpr int kGlyphHeight = 10;

// Pixels outside the image are clipped; alpha in [0, 1] blends over what is there.
void BlendPixel(Image* image, int x, int y, const Rgb& color, float alpha = 1.0f);
void FillRect(Image* image, int x0, int y0, int width, int height, const Rgb& color);
// A line of the given width (pixels) with soft edges, between pixel-centre positions.
void DrawLine(Image* image, double x0, double y0, double x1, double y1, const Rgb& color,
              double width = 1.0);
enum class Marker { kCircle, kSquare, kTriangle, kDiamond };
void DrawMarker(Image* image, double x, double y, Marker marker, double radius,
                const Rgb& color);
// Text with its top-left corner at (x, y); every glyph pixel becomes scale x scale.
void DrawText(Image* image, int x, int y, const std::string& text, const Rgb& color,
              int scale = 1);
int TextWidth(const std::string& text, int scale = 1);
// The same text turned 90 degrees counter-clockwise (for a vertical axis title), its
// bottom-left corner at (x, y + TextWidth).
void DrawTextVertical(Image* image, int x, int y, const std::string& text,
                      const Rgb& color, int scale = 1);

// Bilinear resampling to width x height (area-averaged first when shrinking by more than
// 2x, so thumbnails do not alias). Channels are kept.
Image ResizeImage(const Image& image, int width, int height);
// Copies `tile` into `canvas` with its top-left corner at (x, y) (clipped); grey tiles
// are spread over RGB.
void Blit(Image* canvas, const Image& tile, int x, int y);

}  // namespace fvs::eval
