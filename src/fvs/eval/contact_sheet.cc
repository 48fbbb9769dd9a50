#include "fvs/eval/contact_sheet.h"

#include <algorithm>

#include "fvs/eval/draw.h"
#include "fvs/eval/report.h"

namespace fvs::eval {
namespace {

constexpr int kPad = 8;
constexpr int kLine = kGlyphHeight + 4;
const Rgb kInk{0.1f, 0.1f, 0.1f};
const Rgb kError{0.75f, 0.1f, 0.1f};

}  // namespace

Image MakeContactSheet(const std::string& title, const std::vector<ViewResult>& results,
                       const std::vector<ViewThumbnails>& thumbnails) {
  auto find_thumbnail = [&](const std::string& target) -> const ViewThumbnails* {
    for (const ViewThumbnails& t : thumbnails) {
      if (t.target == target) return &t;
    }
    return nullptr;
  };
  int tile_w = 1, height = kPad + 2 * kLine, label_w = TextWidth(title);
  for (const ViewResult& r : results) {
    height += kLine + kPad;
    label_w = std::max(label_w, TextWidth(r.target + "  ERROR: " + r.error));
    if (const ViewThumbnails* t = find_thumbnail(r.target)) {
      tile_w = std::max({tile_w, t->rendered.width, t->truth.width});
      height += std::max(t->rendered.height, t->truth.height);
    }
  }
  const int width = std::max(3 * kPad + 2 * tile_w, std::min(label_w, 4000) + 2 * kPad);
  Image sheet(width, height + kPad, 3, 1.0f);
  DrawText(&sheet, kPad, kPad, title, kInk);
  DrawText(&sheet, kPad, kPad + kLine, "rendered", kInk);
  DrawText(&sheet, 2 * kPad + tile_w, kPad + kLine, "photo (ground truth)", kInk);
  int y = kPad + 2 * kLine;
  for (const ViewResult& r : results) {
    const std::string label =
        r.ok()
            ? r.target + "  PSNR " + FormatNumber(r.psnr, 2) + "  SSIM " +
                  FormatNumber(r.ssim, 3) + "  LPIPS " + FormatNumber(r.lpips, 3) + "  " +
                  FormatNumber(r.seconds, 2) + " s  K " + std::to_string(r.sources_used)
            : r.target + (r.skipped ? "  SKIPPED: " : "  ERROR: ") + r.error;
    DrawText(&sheet, kPad, y, label, r.ok() ? kInk : kError);
    y += kLine;
    if (const ViewThumbnails* t = find_thumbnail(r.target)) {
      Blit(&sheet, t->rendered, kPad, y);
      Blit(&sheet, t->truth, 2 * kPad + tile_w, y);
      y += std::max(t->rendered.height, t->truth.height);
    }
    y += kPad;
  }
  return sheet;
}

Image StackVertically(const std::vector<Image>& images) {
  int width = 1, height = 0;
  for (const Image& image : images) {
    width = std::max(width, image.width);
    height += image.height;
  }
  Image out(width, std::max(1, height), 3, 1.0f);
  int y = 0;
  for (const Image& image : images) {
    Blit(&out, image, 0, y);
    y += image.height;
  }
  return out;
}

}  // namespace fvs::eval
