#include "fvs/eval/metrics.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fvs/util/error.h"

namespace fvs::eval {
namespace {

constexpr int kRadius = 5;  // 11x11 window
constexpr double kSigma = 1.5;

void CheckSameSize(const Image& a, const Image& b, const Image* mask, const char* what) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
    throw Error(what, "images differ in size: " + std::to_string(a.width) + "x" +
                          std::to_string(a.height) + "x" + std::to_string(a.channels) +
                          " vs " + std::to_string(b.width) + "x" +
                          std::to_string(b.height) + "x" + std::to_string(b.channels));
  }
  if (a.empty()) throw Error(what, "empty image");
  if (mask &&
      (mask->width != a.width || mask->height != a.height || mask->channels != 1)) {
    throw Error(what, "mask size differs from the images");
  }
}

std::vector<double> GaussianKernel() {
  std::vector<double> k(2 * kRadius + 1);
  double sum = 0;
  for (int i = -kRadius; i <= kRadius; ++i) {
    k[i + kRadius] = std::exp(-(i * i) / (2 * kSigma * kSigma));
    sum += k[i + kRadius];
  }
  for (double& v : k) v /= sum;
  return k;
}

// Separable 'valid' filtering of one channel: output (w - 2r) x (h - 2r).
std::vector<double> FilterValid(const std::vector<double>& in, int w, int h,
                                const std::vector<double>& k) {
  const int ow = w - 2 * kRadius, oh = h - 2 * kRadius;
  std::vector<double> tmp(static_cast<size_t>(ow) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < ow; ++x) {
      double s = 0;
      for (int i = 0; i <= 2 * kRadius; ++i)
        s += k[i] * in[static_cast<size_t>(y) * w + x + i];
      tmp[static_cast<size_t>(y) * ow + x] = s;
    }
  }
  std::vector<double> out(static_cast<size_t>(ow) * oh);
  for (int y = 0; y < oh; ++y) {
    for (int x = 0; x < ow; ++x) {
      double s = 0;
      for (int i = 0; i <= 2 * kRadius; ++i)
        s += k[i] * tmp[static_cast<size_t>(y + i) * ow + x];
      out[static_cast<size_t>(y) * ow + x] = s;
    }
  }
  return out;
}

}  // namespace

Image QuantizeTo8Bit(const Image& image) {
  Image out = image;
  for (float& v : out.data) {
    const float c = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    v = std::round(c * 255.0f) / 255.0f;
  }
  return out;
}

double MeanSquaredError(const Image& a, const Image& b, const Image* mask) {
  CheckSameSize(a, b, mask, "MSE");
  double sum = 0;
  size_t count = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (mask && mask->at(x, y) <= 0.5f) continue;
      for (int c = 0; c < a.channels; ++c) {
        const double d = static_cast<double>(a.at(x, y, c)) - b.at(x, y, c);
        sum += d * d;
      }
      count += a.channels;
    }
  }
  if (count == 0) throw Error("MSE", "the mask selects no pixel");
  return sum / count;
}

double Psnr(const Image& a, const Image& b, const Image* mask) {
  const double mse = MeanSquaredError(a, b, mask);
  if (!(mse > 0)) return kMaxPsnr;
  return std::min(kMaxPsnr, -10.0 * std::log10(mse));
}

double Ssim(const Image& a, const Image& b, const Image* mask) {
  CheckSameSize(a, b, mask, "SSIM");
  const int w = a.width, h = a.height;
  if (w < 2 * kRadius + 1 || h < 2 * kRadius + 1) {
    throw Error("SSIM", "images must be at least 11x11 pixels");
  }
  const std::vector<double> k = GaussianKernel();
  constexpr double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03;
  const int ow = w - 2 * kRadius, oh = h - 2 * kRadius;
  const size_t n = static_cast<size_t>(w) * h;
  double total = 0;
  for (int c = 0; c < a.channels; ++c) {
    std::vector<double> x(n), y(n), xx(n), yy(n), xy(n);
    for (size_t i = 0; i < n; ++i) {
      x[i] = a.data[i * a.channels + c];
      y[i] = b.data[i * b.channels + c];
      xx[i] = x[i] * x[i];
      yy[i] = y[i] * y[i];
      xy[i] = x[i] * y[i];
    }
    const auto mx = FilterValid(x, w, h, k), my = FilterValid(y, w, h, k);
    const auto sxx = FilterValid(xx, w, h, k), syy = FilterValid(yy, w, h, k),
               sxy = FilterValid(xy, w, h, k);
    double sum = 0;
    size_t count = 0;
    for (int yy_ = 0; yy_ < oh; ++yy_) {
      for (int xx_ = 0; xx_ < ow; ++xx_) {
        if (mask && mask->at(xx_ + kRadius, yy_ + kRadius) <= 0.5f) continue;
        const size_t i = static_cast<size_t>(yy_) * ow + xx_;
        const double vx = sxx[i] - mx[i] * mx[i];
        const double vy = syy[i] - my[i] * my[i];
        const double cov = sxy[i] - mx[i] * my[i];
        sum += ((2 * mx[i] * my[i] + C1) * (2 * cov + C2)) /
               ((mx[i] * mx[i] + my[i] * my[i] + C1) * (vx + vy + C2));
        ++count;
      }
    }
    if (count == 0) throw Error("SSIM", "the mask selects no window centre");
    total += sum / count;
  }
  return total / a.channels;
}

}  // namespace fvs::eval
