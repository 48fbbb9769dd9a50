// Image files (PNG, JPEG, TIFF, ... through OpenImageIO) to and from fvs::Image.
#pragma once

#include <string>

#include "fvs/util/image.h"

namespace fvs::colmap {

// fvs::Image is spelled out: inside fvs::colmap, `Image` is the sparse model's image
// (reconstruction.h), and a file including both must see the same declarations.

// Colours as float in [0, 1]. channels = 3 converts grey to RGB and drops alpha; 1
// converts to grey (luma); 0 keeps the file's channels. Throws fvs::Error naming the
// file, also before allocating when the file's or the result's values would exceed 2^28
// (an 89-megapixel RGB photo; larger claims are corrupt headers in practice).
fvs::Image ReadImage(const std::string& path, int channels = 3);
// Size without decoding the pixels.
void ReadImageSize(const std::string& path, int* width, int* height);
// A finished output image: the file exists, has this size and decodes (a truncated file
// does not). Never throws. Lets interrupted renders resume at the first missing image.
bool IsCompleteImage(const std::string& path, int width, int height);
// 8-bit PNG/JPEG by extension (values clamped to [0,1] and rounded), 16-bit when the
// extension is .png and bits == 16; float for .exr/.tif with bits == 32. Atomic.
void WriteImage(const std::string& path, const fvs::Image& image, int bits = 8);

}  // namespace fvs::colmap
