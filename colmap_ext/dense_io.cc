// COLMAP's dense-map and fused-visibility files (src/mvs/mat.h Mat<float>::Read/Write and
// src/mvs/fusion.cc WritePointsVisibility in 3.8).
#include "colmap_ext/dense_io.h"

#include <cmath>
#include <cstring>

#include "colmap_ext/binary_buffer.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

// Parses one decimal field of the "W&H&C&" header that ends at '&'.
uint64_t ParseHeaderField(const std::string& data, size_t* pos, const std::string& path,
                          const char* what) {
  uint64_t value = 0;
  size_t digits = 0;
  while (*pos < data.size() && data[*pos] >= '0' && data[*pos] <= '9') {
    if (digits >= 10)
      throw Error(path, std::string("bad header: ") + what + " too large");
    value = value * 10 + (data[*pos] - '0');
    ++digits;
    ++*pos;
  }
  if (digits == 0 || *pos >= data.size() || data[*pos] != '&') {
    throw Error(path, std::string("bad header: expected \"WIDTH&HEIGHT&CHANNELS&\", ") +
                          what + " is not a number followed by '&' (wrong file type?)");
  }
  ++*pos;
  return value;
}

}  // namespace

fvs::Image ReadColmapArray(const std::string& path) {
  const std::string data = ReadFileToString(path);
  size_t pos = 0;
  const uint64_t width = ParseHeaderField(data, &pos, path, "width");
  const uint64_t height = ParseHeaderField(data, &pos, path, "height");
  const uint64_t channels = ParseHeaderField(data, &pos, path, "channels");
  if (width == 0 || height == 0 || channels == 0) {
    throw Error(path, "bad header: zero width, height or channels");
  }
  if (width > (1u << 20) || height > (1u << 20) || channels > 64) {
    throw Error(path, "bad header: implausible size " + std::to_string(width) + "x" +
                          std::to_string(height) + "x" + std::to_string(channels));
  }
  const uint64_t count = width * height * channels;
  const uint64_t body = data.size() - pos;
  if (body != count * sizeof(float)) {
    throw Error(path, std::string(body < count * 4 ? "truncated" : "corrupt") +
                          " file: header says " + std::to_string(width) + "x" +
                          std::to_string(height) + "x" + std::to_string(channels) + " (" +
                          std::to_string(count * 4) + " bytes of data) but " +
                          std::to_string(body) + " bytes follow the header");
  }
  Image image(static_cast<int>(width), static_cast<int>(height),
              static_cast<int>(channels));
  const char* src = data.data() + pos;
  const size_t plane = static_cast<size_t>(width) * height;
  const bool swap = !internal::HostIsLittleEndian();
  for (size_t c = 0; c < channels; ++c) {
    for (size_t i = 0; i < plane; ++i) {
      float v;
      std::memcpy(&v, src + (c * plane + i) * sizeof(float), sizeof(float));
      if (swap) v = internal::ByteSwapped(v);
      if (!std::isfinite(v)) {
        throw Error(path, "non-finite value at pixel (" + std::to_string(i % width) +
                              ", " + std::to_string(i / width) + ") channel " +
                              std::to_string(c));
      }
      image.data[i * channels + c] = v;
    }
  }
  return image;
}

void WriteColmapArray(const std::string& path, const fvs::Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.data.size() !=
          static_cast<size_t>(image.width) * image.height * image.channels) {
    throw Error(path, "cannot write an empty or inconsistent image");
  }
  for (const float v : image.data) {
    if (!std::isfinite(v))
      throw Error(path, "refusing to write a map with NaN/Inf values");
  }
  WriteFileAtomic(path, [&](std::ostream& out) {
    out << image.width << "&" << image.height << "&" << image.channels << "&";
    const size_t plane = static_cast<size_t>(image.width) * image.height;
    std::vector<float> buffer(plane);
    for (int c = 0; c < image.channels; ++c) {
      for (size_t i = 0; i < plane; ++i) {
        const float v = image.data[i * image.channels + c];
        buffer[i] = internal::HostIsLittleEndian() ? v : internal::ByteSwapped(v);
      }
      out.write(reinterpret_cast<const char*>(buffer.data()), plane * sizeof(float));
    }
  });
}

std::vector<std::vector<uint32_t>> ReadFusedVisibility(const std::string& path) {
  internal::BinaryReader in(path, ReadFileToString(path));
  const uint64_t num_points = in.ReadCount("number of points", sizeof(uint32_t));
  std::vector<std::vector<uint32_t>> visibility(num_points);
  for (auto& images : visibility) {
    const uint32_t n = in.Read<uint32_t>("visibility count");
    if (n > in.remaining() / sizeof(uint32_t)) {
      in.Fail("corrupt or truncated file: visibility count " + std::to_string(n) +
              " exceeds the bytes left");
    }
    images.resize(n);
    for (uint32_t& id : images) id = in.Read<uint32_t>("image index");
  }
  in.ExpectEnd();
  return visibility;
}

void WriteFusedVisibility(const std::string& path,
                          const std::vector<std::vector<uint32_t>>& visibility) {
  WriteFileAtomic(path, [&](std::ostream& out) {
    internal::WriteLE<uint64_t>(out, visibility.size());
    for (const auto& images : visibility) {
      internal::WriteLE<uint32_t>(out, static_cast<uint32_t>(images.size()));
      for (const uint32_t id : images) internal::WriteLE<uint32_t>(out, id);
    }
  });
}

}  // namespace fvs::colmap
