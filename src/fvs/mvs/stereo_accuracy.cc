#include "fvs/mvs/stereo_accuracy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fvs/util/error.h"

namespace fvs::mvs {
namespace {

constexpr double kEdges[DepthErrorHistogram::kNumBins - 2] = {0.001, 0.002, 0.005, 0.01,
                                                              0.02,  0.05,  0.1};
const char* const kBinNames[DepthErrorHistogram::kNumBins] = {
    "<=0.1%", "<=0.2%", "<=0.5%", "<=1%", "<=2%", "<=5%", "<=10%", ">10%", "no depth"};

}  // namespace

std::vector<uint8_t> TexturedMask(const Image& grey, float min_gradient, int radius) {
  Require(grey.channels == 1, "TexturedMask", "needs a 1-channel image");
  const int w = grey.width, h = grey.height;
  std::vector<float> grad(static_cast<size_t>(w) * h, 0.f);
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      const float gx = 0.5f * (grey.at(x + 1, y) - grey.at(x - 1, y));
      const float gy = 0.5f * (grey.at(x, y + 1) - grey.at(x, y - 1));
      grad[static_cast<size_t>(y) * w + x] = std::sqrt(gx * gx + gy * gy);
    }
  }
  std::vector<uint8_t> mask(grad.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float m = 0;
      for (int yy = std::max(0, y - radius); yy <= std::min(h - 1, y + radius); ++yy) {
        for (int xx = std::max(0, x - radius); xx <= std::min(w - 1, x + radius); ++xx) {
          m = std::max(m, grad[static_cast<size_t>(yy) * w + xx]);
        }
      }
      mask[static_cast<size_t>(y) * w + x] = m >= min_gradient ? 1 : 0;
    }
  }
  return mask;
}

void DepthErrorHistogram::Add(double depth, double gt) {
  ++total_;
  if (!(depth > 0) || !std::isfinite(depth)) {
    ++counts_[kNumBins - 1];
    return;
  }
  const double e = std::abs(depth - gt) / gt;
  int b = 0;
  while (b < kNumBins - 2 && e > kEdges[b]) ++b;
  ++counts_[b];
}

void DepthErrorHistogram::Add(const Image& depth, const Image& gt,
                              const std::vector<uint8_t>& mask) {
  Require(depth.width == gt.width && depth.height == gt.height && depth.channels == 1 &&
              gt.channels == 1,
          "DepthErrorHistogram", "depth and ground truth differ in size");
  Require(mask.empty() || mask.size() == gt.data.size(), "DepthErrorHistogram",
          "mask differs in size");
  for (size_t i = 0; i < gt.data.size(); ++i) {
    if (!(gt.data[i] > 0) || (!mask.empty() && !mask[i])) continue;
    Add(depth.data[i], gt.data[i]);
  }
}

double DepthErrorHistogram::Fraction(int bin) const {
  return total_ ? static_cast<double>(counts_[bin]) / total_ : 0.0;
}

double DepthErrorHistogram::FractionWithin(double relative_error) const {
  int64_t n = 0;
  for (int b = 0; b < kNumBins - 2 && kEdges[b] <= relative_error * (1 + 1e-12); ++b) {
    n += counts_[b];
  }
  return total_ ? static_cast<double>(n) / total_ : 0.0;
}

std::string DepthErrorHistogram::ToString(const std::string& label) const {
  char line[160];
  std::snprintf(line, sizeof(line), "%s: %lld pixels, within 1%%: %.4f\n", label.c_str(),
                static_cast<long long>(total_), FractionWithin(0.01));
  std::string out = line;
  for (int b = 0; b < kNumBins; ++b) {
    std::snprintf(line, sizeof(line), "    %-9s %.4f\n", kBinNames[b], Fraction(b));
    out += line;
  }
  return out;
}

}  // namespace fvs::mvs
