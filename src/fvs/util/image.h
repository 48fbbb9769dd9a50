// Dense float images, interleaved (row-major, channels last), the common currency between
// stages: colours in [0, 1], depths in scene units (0 = no surface).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fvs {

template <typename T>
struct ImageT {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<T> data;

  ImageT() = default;
  ImageT(int w, int h, int c, T fill = T(0))
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}

  bool empty() const { return data.empty(); }
  size_t Index(int x, int y, int c = 0) const {
    return (static_cast<size_t>(y) * width + x) * channels + c;
  }
  T& at(int x, int y, int c = 0) { return data[Index(x, y, c)]; }
  const T& at(int x, int y, int c = 0) const { return data[Index(x, y, c)]; }
  T* row(int y) { return data.data() + static_cast<size_t>(y) * width * channels; }
  const T* row(int y) const {
    return data.data() + static_cast<size_t>(y) * width * channels;
  }
};

using Image = ImageT<float>;
using ImageU8 = ImageT<uint8_t>;

}  // namespace fvs
