// Minimal little-endian TIFFs (8-bit grey, uncompressed) of the shapes image_fuzzer found
// OpenImageIO misreading. Shared by the unit tests of ReadImage and the fuzz seeds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace fvs::testing {

// One TIFF directory entry of a single SHORT (type 3) or LONG (type 4) value.
struct TiffEntry {
  uint16_t tag, type;
  uint32_t value;
};

// A little-endian TIFF: the header, one directory of `entries` (in tag order), zeros up
// to byte 200, where the pixel data goes.
template <size_t kCount>
std::string TiffBytes(const TiffEntry (&entries)[kCount], const std::string& data) {
  std::string bytes = "II*";
  auto put = [&bytes](uint64_t value, int size) {
    for (int i = 0; i < size; ++i) bytes += static_cast<char>((value >> (8 * i)) & 0xff);
  };
  put(0, 1);
  put(8, 4);  // the directory follows the header
  put(kCount, 2);
  for (const TiffEntry& e : entries) {
    put(e.tag, 2);
    put(e.type, 2);
    put(1, 4);                          // one value
    put(e.value, e.type == 3 ? 2 : 4);  // left-justified in the 4-byte field
    if (e.type == 3) put(0, 2);
  }
  put(0, 4);  // no next directory
  bytes.resize(200, '\0');
  return bytes + data;
}

// 64 x 64 pixels claiming tiles of tile_size x tile_size (OpenImageIO allocated a whole
// claimed tile); with tile_size 64 a valid file (one tile, all 0x55), larger claims carry
// 16 bytes of data.
inline std::string TiledTiffBytes(uint32_t tile_size) {
  const uint32_t data_bytes = tile_size == 64 ? 64 * 64 : 16;
  // Tags: width, height, bits, compression, photometric, samples per pixel, planar
  // configuration, tile width, tile length, tile offsets, tile byte counts.
  const TiffEntry entries[] = {{256, 3, 64},  {257, 3, 64},        {258, 3, 8},
                               {259, 3, 1},   {262, 3, 1},         {277, 3, 1},
                               {284, 3, 1},   {322, 4, tile_size}, {323, 4, tile_size},
                               {324, 4, 200}, {325, 4, data_bytes}};
  return TiffBytes(entries, std::string(data_bytes, '\x55'));
}

// width x height pixels in strips of 3 rows, of which the file gives one offset and 16
// bytes of data: OpenImageIO reads the strips it lacks as zeros, without an error (the
// shape of a 179-byte TIFF image_fuzzer found claiming 16 396 x 13 408 pixels).
inline std::string StrippedTiffBytes(uint32_t width, uint32_t height) {
  // Tags: width, height, bits, compression, photometric, strip offsets, samples per
  // pixel, rows per strip, strip byte counts.
  const TiffEntry entries[] = {{256, 4, width}, {257, 4, height}, {258, 3, 8},
                               {259, 3, 1},     {262, 3, 1},      {273, 4, 200},
                               {277, 3, 1},     {278, 3, 3},      {279, 4, 16}};
  return TiffBytes(entries, std::string(16, '\x55'));
}

}  // namespace fvs::testing
