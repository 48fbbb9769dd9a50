// COLMAP dense-workspace files: depth and normal maps (.bin: ASCII "W&H&C&" header, then
// little-endian float32, row-major, channels planar) and fused.ply.vis (visibility of
// each fused point: uint64 count, then per point uint32 count + uint32 image indices).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/util/image.h"

namespace fvs::colmap {

// fvs::Image is spelled out: inside fvs::colmap, `Image` is the sparse model's image
// (reconstruction.h), and a file including both must see the same declarations.

// Returns an interleaved fvs::Image (channels 1 for depth, 3 for normals). Throws
// fvs::Error on a bad header, a truncated body or trailing bytes.
fvs::Image ReadColmapArray(const std::string& path);
// Writes atomically (temp file + rename).
void WriteColmapArray(const std::string& path, const fvs::Image& image);

std::vector<std::vector<uint32_t>> ReadFusedVisibility(const std::string& path);
void WriteFusedVisibility(const std::string& path,
                          const std::vector<std::vector<uint32_t>>& visibility);

}  // namespace fvs::colmap
