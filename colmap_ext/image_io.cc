// Image files through OpenImageIO. Writes go to a temporary name that keeps the extension
// (OIIO picks the format from it) and are renamed into place.
#include "colmap_ext/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

namespace OIIO = OIIO_NAMESPACE;

constexpr int64_t kMaxImageValues = int64_t{1} << 28;
constexpr uint64_t kMaxScanlineBytes = uint64_t{1} << 20;
constexpr int64_t kMaxTileValues = int64_t{1} << 24;

std::unique_ptr<OIIO::ImageInput> OpenInput(const std::string& path) {
  auto input = OIIO::ImageInput::open(path);
  if (!input) {
    std::string message = OIIO::geterror();
    if (message.empty()) message = "cannot open image";
    throw Error(path, "cannot read image (" + message + ")");
  }
  return input;
}

std::string Extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext;
}

// The pixels a header claims, before anything is allocated for them.
void CheckClaimedSize(const std::string& path, const OIIO::ImageSpec& spec,
                      int channels) {
  // A header may claim any size (an 81-byte PBM claimed 51 GB of pixels, a 17-byte one
  // 77 777 777 x 6 grey pixels that read as RGB made 5.6 GB: image_fuzzer). Refuse before
  // allocating when the file's values or the result's exceed 2^28 (1 GiB of floats each:
  // an 89-megapixel RGB photo), so a read never holds more than about 2 GiB.
  // (Width times height fits 63 bits; times the channels might not, hence the division.)
  const int64_t pixels = static_cast<int64_t>(spec.width) * spec.height;
  if (pixels > kMaxImageValues / std::max(spec.nchannels, channels)) {
    throw Error(path, "image of " + std::to_string(spec.width) + "x" +
                          std::to_string(spec.height) + " with " +
                          std::to_string(spec.nchannels) +
                          " channels is too large (over 2^28 values; corrupt header?)");
  }
  // A band is at least one row, and OpenImageIO's read_scanlines (still used for files
  // with a type per channel) converts at least 256 rows per call whatever the height (a
  // 26-byte PBM of 21 474 837 x 7 pixels made it allocate 5.5 GB: image_fuzzer), so a
  // scanline of over 1 MiB in the file's own format (a 349 525-pixel-wide 8-bit RGB row)
  // is refused too.
  if (spec.scanline_bytes(true) > kMaxScanlineBytes) {
    throw Error(path, "image of " + std::to_string(spec.width) + "x" +
                          std::to_string(spec.height) +
                          " is too wide (over 1 MiB per row; corrupt header?)");
  }
  // Tiled files are converted a tile at a time (a TIFF claiming tiles of 65 536 x 65 536
  // grey pixels made OpenImageIO allocate 17 GB): tiles over 2^24 values (a 2 048 x 2 048
  // RGBA tile; real ones are 64 to 1 024 pixels square) are refused.
  const int64_t tile_pixels = static_cast<int64_t>(spec.tile_width) * spec.tile_height;
  if (spec.tile_width > 0 && (spec.tile_height <= 0 || spec.tile_depth > 1 ||
                              tile_pixels > kMaxTileValues / spec.nchannels)) {
    throw Error(path, "tiles of " + std::to_string(spec.tile_width) + "x" +
                          std::to_string(spec.tile_height) +
                          " pixels are too large (over 2^24 values; corrupt header?)");
  }
}

// Decodes band by band into a buffer that grows with what was decoded: the capacity is
// only reserved (address space), and each band is zero-filled just before it is read, so
// a header claiming far more pixels than the file holds costs one band, not the claim (a
// 69-byte PBM claiming 21 473 x 6 836 pixels spent 7 s filling 590 MB: image_fuzzer).
// A band holds at most 2^22 values (16 MiB as floats), or one row of tiles. Scanlines of
// one sample type are read in the file's own format and converted here, as OpenImageIO's
// read_scanlines does, but without its conversion buffer: that is 64 MiB per call
// whatever the rows asked for (narrow images read band by band spent 17 s allocating it
// under ASan: image_fuzzer).
fvs::Image DecodeInBands(OIIO::ImageInput& input, const std::string& path) {
  const OIIO::ImageSpec spec = input.spec();
  fvs::Image file;
  file.width = spec.width;
  file.height = spec.height;
  file.channels = spec.nchannels;
  const size_t row_values = static_cast<size_t>(spec.width) * spec.nchannels;
  file.data.reserve(row_values * spec.height);
  const bool tiled = spec.tile_width > 0;
  const bool native = !tiled && spec.channelformats.empty();
  const int band =
      tiled ? spec.tile_height
            : static_cast<int>(std::max<size_t>(
                  1, std::min<size_t>(spec.height, (size_t{1} << 22) / row_values)));
  std::vector<unsigned char> raw;  // one band in the file's format (native reads)
  for (int y0 = 0; y0 < spec.height; y0 += band) {
    const int y1 = std::min(spec.height, y0 + band);
    file.data.resize(row_values * y1);
    float* rows = file.data.data() + row_values * y0;
    const size_t values = row_values * (y1 - y0);
    bool ok = false;
    if (native) {
      raw.resize(values * spec.format.size());
      ok = input.read_native_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z,
                                       raw.data()) &&
           OIIO::convert_pixel_values(spec.format, raw.data(), OIIO::TypeDesc::FLOAT,
                                      rows, static_cast<int>(values));
    } else if (tiled) {
      ok = input.read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y0, spec.y + y1,
                            spec.z, spec.z + 1, 0, spec.nchannels, OIIO::TypeDesc::FLOAT,
                            rows);
    } else {
      ok = input.read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                OIIO::TypeDesc::FLOAT, rows);
    }
    if (!ok) throw Error(path, "cannot decode image (" + input.geterror() + ")");
  }
  return file;
}

}  // namespace

fvs::Image ReadImage(const std::string& path, int channels) {
  if (channels != 0 && channels != 1 && channels != 3) {
    throw Error(path, "ReadImage: channels must be 0, 1 or 3");
  }
  auto input = OpenInput(path);
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1) {
    throw Error(path, "unsupported image (empty, or a volume)");
  }
  CheckClaimedSize(path, spec, channels);
  Image file = DecodeInBands(*input, path);
  input->close();
  for (float& v : file.data) {
    if (!std::isfinite(v)) v = 0.0f;  // no NaN/Inf leaves a stage
  }
  const int n = spec.nchannels;
  if (channels == 0 || channels == n) return file;
  // Alpha is dropped; grey images are replicated to RGB; RGB to grey by Rec. 601 luma.
  Image out(spec.width, spec.height, channels);
  const size_t num_pixels = static_cast<size_t>(spec.width) * spec.height;
  for (size_t i = 0; i < num_pixels; ++i) {
    const float* src = &file.data[i * n];
    float rgb[3];
    if (n < 3) {
      rgb[0] = rgb[1] = rgb[2] = src[0];
    } else {
      rgb[0] = src[0];
      rgb[1] = src[1];
      rgb[2] = src[2];
    }
    if (channels == 3) {
      for (int c = 0; c < 3; ++c) out.data[i * 3 + c] = rgb[c];
    } else {
      out.data[i] = n < 3 ? src[0] : 0.299f * rgb[0] + 0.587f * rgb[1] + 0.114f * rgb[2];
    }
  }
  return out;
}

void ReadImageSize(const std::string& path, int* width, int* height) {
  auto input = OpenInput(path);
  *width = input->spec().width;
  *height = input->spec().height;
  input->close();
}

bool IsCompleteImage(const std::string& path, int width, int height) {
  if (!std::filesystem::exists(path)) return false;
  try {
    int w = 0, h = 0;
    ReadImageSize(path, &w, &h);
    if (w != width || h != height) return false;
    ReadImage(path);  // decodes: a truncated file fails here
    return true;
  } catch (const Error&) {
    return false;
  }
}

void WriteImage(const std::string& path, const fvs::Image& image, int bits) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.data.size() !=
          static_cast<size_t>(image.width) * image.height * image.channels) {
    throw Error(path, "cannot write an empty or inconsistent image");
  }
  const std::string ext = Extension(path);
  if (ext.empty())
    throw Error(path, "image file name needs an extension (.png, .jpg, ...)");
  OIIO::TypeDesc type = OIIO::TypeDesc::UINT8;
  bool clamp = true;
  if (bits == 16 && (ext == "png" || ext == "tif" || ext == "tiff")) {
    type = OIIO::TypeDesc::UINT16;
  } else if (bits == 32 && (ext == "exr" || ext == "tif" || ext == "tiff")) {
    type = OIIO::TypeDesc::FLOAT;
    clamp = false;
  } else if (bits != 8) {
    throw Error(path,
                "cannot write " + std::to_string(bits) + "-bit ." + ext + " images");
  }
  std::vector<float> pixels = image.data;
  for (float& v : pixels) {
    if (!std::isfinite(v)) throw Error(path, "refusing to write an image with NaN/Inf");
    if (clamp) v = std::min(1.0f, std::max(0.0f, v));
  }
  // The temporary name keeps the extension: OIIO chooses the format from it.
  const std::string temp = TempPathFor(path) + "." + ext;
  auto output = OIIO::ImageOutput::create(temp);
  if (!output)
    throw Error(path, "no image writer for ." + ext + " (" + OIIO::geterror() + ")");
  OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
  if (ext == "jpg" || ext == "jpeg") spec.attribute("CompressionQuality", 95);
  bool ok = output->open(temp, spec);
  // OIIO converts float to the file's integer type by rounding to nearest.
  ok = ok && output->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
  ok = output->close() && ok;
  if (!ok) {
    const std::string message = output->geterror();
    std::remove(temp.c_str());
    throw Error(path, "cannot write image (" + message + ")");
  }
  CommitTempFile(temp, path);
}

}  // namespace fvs::colmap
