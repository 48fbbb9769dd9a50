#include "fvs/util/image_resize.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fvs/util/error.h"

namespace fvs {

std::pair<int, int> ScaledSize(int width, int height, int max_side, int min_side) {
  const double s = std::min(1.0, static_cast<double>(max_side) / std::max(width, height));
  return {std::max(min_side, static_cast<int>(std::lround(width * s))),
          std::max(min_side, static_cast<int>(std::lround(height * s)))};
}

namespace {

// Weights of input samples [0, in) for each output sample along one axis: the overlap of
// output pixel o's footprint [o, o+1) * in/out with every input pixel.
struct AxisWeights {
  std::vector<int> first;                  // per output: first input index
  std::vector<std::vector<float>> weight;  // per output: weights, sum 1
};

AxisWeights FootprintWeights(int in, int out) {
  AxisWeights a;
  a.first.resize(out);
  a.weight.resize(out);
  const double ratio = static_cast<double>(in) / out;
  for (int o = 0; o < out; ++o) {
    double lo = o * ratio, hi = (o + 1) * ratio;
    if (ratio < 1) {  // enlargement: nearest input pixel
      const int i = std::min(in - 1, static_cast<int>((o + 0.5) * ratio));
      a.first[o] = i;
      a.weight[o] = {1.f};
      continue;
    }
    const int i0 = static_cast<int>(std::floor(lo));
    const int i1 = std::min(in - 1, static_cast<int>(std::ceil(hi)) - 1);
    a.first[o] = i0;
    double total = 0;
    for (int i = i0; i <= i1; ++i) {
      const double w = std::min<double>(hi, i + 1) - std::max<double>(lo, i);
      a.weight[o].push_back(static_cast<float>(std::max(0.0, w)));
      total += std::max(0.0, w);
    }
    for (float& w : a.weight[o]) w = static_cast<float>(w / total);
  }
  return a;
}

}  // namespace

Image ResizeArea(const Image& image, int width, int height) {
  Require(width > 0 && height > 0 && !image.empty(), "resize", "empty image or size");
  const AxisWeights wx = FootprintWeights(image.width, width);
  const AxisWeights wy = FootprintWeights(image.height, height);
  const int c = image.channels;
  // Horizontal pass into (width x image.height), then vertical.
  Image tmp(width, image.height, c);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (size_t k = 0; k < wx.weight[x].size(); ++k) {
        const float* p = &image.at(wx.first[x] + static_cast<int>(k), y);
        for (int ch = 0; ch < c; ++ch) tmp.at(x, y, ch) += wx.weight[x][k] * p[ch];
      }
    }
  }
  Image out(width, height, c);
  for (int y = 0; y < height; ++y) {
    for (size_t k = 0; k < wy.weight[y].size(); ++k) {
      const float w = wy.weight[y][k];
      const float* src = tmp.row(wy.first[y] + static_cast<int>(k));
      float* dst = out.row(y);
      for (int i = 0; i < width * c; ++i) dst[i] += w * src[i];
    }
  }
  return out;
}

Image BoxBlur(const Image& image, int radius) {
  Require(radius >= 0, "box blur", "negative radius");
  Image out = image;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < image.channels; ++c) {
        float sum = 0;
        int n = 0;
        for (int yy = std::max(0, y - radius); yy <= std::min(image.height - 1, y + radius);
             ++yy) {
          for (int xx = std::max(0, x - radius);
               xx <= std::min(image.width - 1, x + radius); ++xx) {
            sum += image.at(xx, yy, c);
            ++n;
          }
        }
        out.at(x, y, c) = sum / n;
      }
    }
  }
  return out;
}

}  // namespace fvs
