// Image files through OpenImageIO. Writes go to a temporary name that keeps the extension
// (OIIO picks the format from it) and are renamed into place.
#include "colmap_ext/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <system_error>
#include <vector>

#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

namespace OIIO = OIIO_NAMESPACE;

constexpr int64_t kMaxImageValues = int64_t{1} << 28;
constexpr uint64_t kMaxScanlineBytes = uint64_t{1} << 20;
constexpr int64_t kMaxTileValues = int64_t{1} << 24;
constexpr int64_t kMaxValuesPerFileByte = int64_t{1} << 14;

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
  // allocating when the file's values or the result's exceed 2^28 (an 89-megapixel RGB
  // photo): a read holds at most 1 GiB of floats beside one band, and decodes at most
  // 2^28 values whatever the file's compression.
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
  // A file must be able to hold what its header claims. OpenImageIO's TIFF reader invents
  // the strips a file lacks (zeros), so the banded decode below cannot stop at missing
  // data there: a 179-byte TIFF of 16 396 x 13 408 grey pixels took 1.2 GB and 10 s under
  // ASan (image_fuzzer). The codecs photos come in pack fewer than 2^14 values in a
  // byte: deflate stops at 1 032:1 (a 1-bit PNG at about 8 256 values a byte), LZW,
  // PackBits and Huffman-coded JPEG below that; an arithmetic-coded JPEG or a fax of a
  // blank page might pass it and is refused.
  std::error_code error;
  const uintmax_t file_bytes = std::filesystem::file_size(path, error);
  const int64_t values = pixels * spec.nchannels;  // at most 2^28 by the first check
  if (!error && values / kMaxValuesPerFileByte >= static_cast<int64_t>(file_bytes)) {
    throw Error(path,
                "image of " + std::to_string(spec.width) + "x" +
                    std::to_string(spec.height) + " with " +
                    std::to_string(spec.nchannels) + " channels cannot fit in " +
                    std::to_string(file_bytes) +
                    " bytes (over 2^14 values a byte; corrupt header or truncated?)");
  }
}

// No NaN or Inf leaves a stage.
float Finite(float v) { return std::isfinite(v) ? v : 0.0f; }

// Pixels of `n` channels to `channels` (n itself when 0): alpha is dropped, grey is
// replicated to RGB, RGB becomes grey by Rec. 601 luma.
void ConvertChannels(const float* src, int n, size_t pixels, int channels, float* dst) {
  if (channels == 0 || channels == n) {
    for (size_t i = 0; i < pixels * n; ++i) dst[i] = Finite(src[i]);
    return;
  }
  for (size_t i = 0; i < pixels; ++i, src += n) {
    const float r = Finite(src[0]);
    const float g = n < 3 ? r : Finite(src[1]);
    const float b = n < 3 ? r : Finite(src[2]);
    if (channels == 3) {
      *dst++ = r;
      *dst++ = g;
      *dst++ = b;
    } else {
      *dst++ = n < 3 ? r : 0.299f * r + 0.587f * g + 0.114f * b;
    }
  }
}

// Decodes band by band, each band converted at once to the channels asked for, into a
// result whose capacity is only reserved (address space) and grows with what was decoded.
// So a read holds the result and one band: a header claiming far more pixels than the
// file holds costs one band, not the claim (a 69-byte PBM claiming 21 473 x 6 836 pixels
// spent 7 s filling 590 MB), and channels that are dropped are never all held (a 185-byte
// TIFF of 8 x 65 293 pixels with 512 channels, which OpenImageIO decodes as zeros, held
// 1 GiB of floats for a 6 MB RGB result: image_fuzzer).
// A band holds at most 2^22 values (16 MiB as floats), or one row of tiles. Scanlines of
// one sample type are read in the file's own format and converted here, as OpenImageIO's
// read_scanlines does, but without its conversion buffer: that is 64 MiB per call
// whatever the rows asked for (narrow images read band by band spent 17 s allocating it
// under ASan: image_fuzzer).
fvs::Image DecodeInBands(OIIO::ImageInput& input, const std::string& path, int channels) {
  const OIIO::ImageSpec spec = input.spec();
  fvs::Image out;
  out.width = spec.width;
  out.height = spec.height;
  out.channels = channels == 0 ? spec.nchannels : channels;
  out.data.reserve(static_cast<size_t>(spec.width) * spec.height * out.channels);
  const size_t row_values = static_cast<size_t>(spec.width) * spec.nchannels;
  const bool tiled = spec.tile_width > 0;
  const bool native = !tiled && spec.channelformats.empty();
  const int band =
      tiled ? spec.tile_height
            : static_cast<int>(std::max<size_t>(
                  1, std::min<size_t>(spec.height, (size_t{1} << 22) / row_values)));
  std::vector<unsigned char> raw;  // one band in the file's format (native reads)
  std::vector<float> rows;         // one band as floats, all of the file's channels
  for (int y0 = 0; y0 < spec.height; y0 += band) {
    const int y1 = std::min(spec.height, y0 + band);
    const size_t values = row_values * (y1 - y0);
    rows.resize(values);
    bool ok = false;
    if (native) {
      raw.resize(values * spec.format.size());
      ok = input.read_native_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z,
                                       raw.data()) &&
           OIIO::convert_pixel_values(spec.format, raw.data(), OIIO::TypeDesc::FLOAT,
                                      rows.data(), static_cast<int>(values));
    } else if (tiled) {
      ok = input.read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y0, spec.y + y1,
                            spec.z, spec.z + 1, 0, spec.nchannels, OIIO::TypeDesc::FLOAT,
                            rows.data());
    } else {
      ok = input.read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, spec.nchannels,
                                OIIO::TypeDesc::FLOAT, rows.data());
    }
    if (!ok) throw Error(path, "cannot decode image (" + input.geterror() + ")");
    const size_t pixels = static_cast<size_t>(spec.width) * (y1 - y0);
    const size_t done = out.data.size();
    out.data.resize(done + pixels * out.channels);
    ConvertChannels(rows.data(), spec.nchannels, pixels, channels,
                    out.data.data() + done);
  }
  return out;
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
  Image image = DecodeInBands(*input, path, channels);
  input->close();
  return image;
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
