// A minimal little-endian tiled TIFF (64 x 64 grey pixels, 8 bits, uncompressed) whose
// header claims tiles of tile_size x tile_size pixels: the shape image_fuzzer found
// making OpenImageIO allocate a whole claimed tile. With tile_size 64 it is a valid file
// (one tile, all 0x55); larger claims carry 16 bytes of data. Shared by the unit test of
// ReadImage and the fuzz seeds.
#pragma once

#include <cstdint>
#include <string>

namespace fvs::testing {

inline std::string TiledTiffBytes(uint32_t tile_size) {
  const uint32_t data_bytes = tile_size == 64 ? 64 * 64 : 16;
  struct Entry {
    uint16_t tag, type;
    uint32_t value;
  };
  // type 3 = SHORT, 4 = LONG; tags: width, height, bits, compression, photometric,
  // samples per pixel, planar configuration, tile width, tile length, tile offsets,
  // tile byte counts.
  const Entry entries[] = {{256, 3, 64},  {257, 3, 64},        {258, 3, 8},
                           {259, 3, 1},   {262, 3, 1},         {277, 3, 1},
                           {284, 3, 1},   {322, 4, tile_size}, {323, 4, tile_size},
                           {324, 4, 200}, {325, 4, data_bytes}};
  std::string bytes = "II*";
  auto put = [&bytes](uint64_t value, int size) {
    for (int i = 0; i < size; ++i) bytes += static_cast<char>((value >> (8 * i)) & 0xff);
  };
  put(0, 1);
  put(8, 4);  // the directory follows the header
  put(sizeof(entries) / sizeof(entries[0]), 2);
  for (const Entry& e : entries) {
    put(e.tag, 2);
    put(e.type, 2);
    put(1, 4);                          // one value
    put(e.value, e.type == 3 ? 2 : 4);  // left-justified in the 4-byte field
    if (e.type == 3) put(0, 2);
  }
  put(0, 4);  // no next directory
  bytes.resize(200, '\0');
  bytes += std::string(data_bytes, '\x55');
  return bytes;
}

}  // namespace fvs::testing
