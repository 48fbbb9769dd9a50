#include "fvs/util/hole_filling.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fvs/util/error.h"

namespace fvs {
namespace {

// One pyramid level: premultiplied colours and weights in [0, 1].
struct Level {
  int width = 0, height = 0;
  std::vector<double> color;  // width * height * channels, premultiplied by weight
  std::vector<double> weight;
};

// Halves a level: each coarse pixel sums its (up to) 2x2 fine pixels; the weight is
// capped at 1 so that a fully covered block does not outvote its neighbours.
Level Push(const Level& fine, int channels) {
  Level coarse;
  coarse.width = (fine.width + 1) / 2;
  coarse.height = (fine.height + 1) / 2;
  coarse.color.assign(static_cast<size_t>(coarse.width) * coarse.height * channels, 0.0);
  coarse.weight.assign(static_cast<size_t>(coarse.width) * coarse.height, 0.0);
  for (int y = 0; y < fine.height; ++y) {
    for (int x = 0; x < fine.width; ++x) {
      const size_t f = static_cast<size_t>(y) * fine.width + x;
      const size_t c = static_cast<size_t>(y / 2) * coarse.width + x / 2;
      coarse.weight[c] += fine.weight[f];
      for (int k = 0; k < channels; ++k) {
        coarse.color[c * channels + k] += fine.color[f * channels + k];
      }
    }
  }
  for (size_t c = 0; c < coarse.weight.size(); ++c) {
    const double w = coarse.weight[c];
    if (w > 1.0) {
      for (int k = 0; k < channels; ++k) coarse.color[c * channels + k] /= w;
      coarse.weight[c] = 1.0;
    }
  }
  return coarse;
}

// Fills the missing weight of every fine pixel from the coarse level (bilinear between
// coarse pixel centres), so that afterwards every fine weight is 1.
void Pull(const Level& coarse, int channels, Level* fine) {
  for (int y = 0; y < fine->height; ++y) {
    // Fine pixel centre in coarse pixel coordinates.
    const double cy = std::clamp((y + 0.5) / 2.0 - 0.5, 0.0, coarse.height - 1.0);
    const int y0 = static_cast<int>(std::floor(cy));
    const int y1 = std::min(y0 + 1, coarse.height - 1);
    const double ay = cy - y0;
    for (int x = 0; x < fine->width; ++x) {
      const size_t f = static_cast<size_t>(y) * fine->width + x;
      const double missing = 1.0 - fine->weight[f];
      if (missing <= 0) continue;
      const double cx = std::clamp((x + 0.5) / 2.0 - 0.5, 0.0, coarse.width - 1.0);
      const int x0 = static_cast<int>(std::floor(cx));
      const int x1 = std::min(x0 + 1, coarse.width - 1);
      const double ax = cx - x0;
      const double w[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
      const size_t at[4] = {static_cast<size_t>(y0) * coarse.width + x0,
                            static_cast<size_t>(y0) * coarse.width + x1,
                            static_cast<size_t>(y1) * coarse.width + x0,
                            static_cast<size_t>(y1) * coarse.width + x1};
      for (int k = 0; k < channels; ++k) {
        double v = 0;
        for (int n = 0; n < 4; ++n) v += w[n] * coarse.color[at[n] * channels + k];
        fine->color[f * channels + k] += missing * v;
      }
      fine->weight[f] = 1.0;
    }
  }
}

// The colours of `color` pushed and pulled from the pixels with weight > 0: every pixel
// of the result has a colour. Empty when no pixel has weight.
std::vector<double> PushPull(const std::vector<double>& weights, const Image& color) {
  const int c = color.channels;
  const size_t n = weights.size();
  Level base;
  base.width = color.width;
  base.height = color.height;
  base.weight = weights;
  base.color.assign(n * c, 0.0);
  bool any = false;
  for (size_t i = 0; i < n; ++i) {
    if (weights[i] <= 0) continue;
    any = true;
    for (int k = 0; k < c; ++k)
      base.color[i * c + k] = weights[i] * color.data[i * c + k];
  }
  if (!any) return {};
  std::vector<Level> pyramid;
  pyramid.push_back(std::move(base));
  while (pyramid.back().width > 1 || pyramid.back().height > 1) {
    pyramid.push_back(Push(pyramid.back(), c));
  }
  // The 1x1 top holds the mean of all weighted colours; normalise it, then pull down.
  Level& top = pyramid.back();
  for (int k = 0; k < c; ++k) top.color[k] /= top.weight[0];
  top.weight[0] = 1.0;
  for (size_t l = pyramid.size() - 1; l-- > 0;) Pull(pyramid[l + 1], c, &pyramid[l]);
  return std::move(pyramid.front().color);
}

}  // namespace

void FillHoles(const Image& coverage, const Image* depth, Image* color) {
  Require(coverage.channels == 1 && coverage.width == color->width &&
              coverage.height == color->height,
          "FillHoles", "coverage must be one channel of the colour's size");
  Require(depth == nullptr || (depth->channels == 1 && depth->width == color->width &&
                               depth->height == color->height),
          "FillHoles", "depth must be one channel of the colour's size");
  const int c = color->channels;
  const size_t n = static_cast<size_t>(color->width) * color->height;
  if (n == 0 || c == 0) return;
  auto no_surface = [&](size_t i) {
    return depth != nullptr && !(depth->data[i] > 0 && std::isfinite(depth->data[i]));
  };
  std::vector<double> weights(n, 0.0), far_weights(n, 0.0);
  bool any_near_hole = false, any_far_hole = false;
  for (size_t i = 0; i < n; ++i) {
    double w = coverage.data[i];
    w = std::isfinite(w) ? std::clamp(w, 0.0, 1.0) : 0.0;
    for (int k = 0; k < c && w > 0; ++k) {
      if (!std::isfinite(color->data[i * c + k])) w = 0;
    }
    weights[i] = w;
    if (no_surface(i)) far_weights[i] = w;
    if (w < 1.0) (no_surface(i) ? any_far_hole : any_near_hole) = true;
  }
  // Holes without a surface (sky, background beyond the mesh) are filled from covered
  // pixels without a surface only, when there are any: a dark backdrop must not take the
  // colour of the lit object in front of it. The pyramid of all covered pixels is built
  // only when some hole needs it (outdoors the holes are usually all sky).
  const std::vector<double> far =
      any_far_hole ? PushPull(far_weights, *color) : std::vector<double>();
  const bool need_all = any_near_hole || (any_far_hole && far.empty());
  const std::vector<double> all =
      need_all ? PushPull(weights, *color) : std::vector<double>();
  if (far.empty() && all.empty()) return;  // no hole, or nothing covered: left as it is
  for (size_t i = 0; i < n; ++i) {
    if (weights[i] >= 1.0) continue;  // fully covered pixels keep their colour exactly
    const std::vector<double>& source = no_surface(i) && !far.empty() ? far : all;
    for (int k = 0; k < c; ++k) {
      color->data[i * c + k] = static_cast<float>(source[i * c + k]);
    }
  }
}

}  // namespace fvs
