// Resampling of float images.
#pragma once

#include "fvs/util/image.h"

namespace fvs {

// Area-weighted resampling (box filter of the exact pixel footprint): the right filter
// for the 4x reduction of training images and the small photos the backdrop fit
// compares; also works for enlargements (nearest).
Image ResizeArea(const Image& image, int width, int height);

}  // namespace fvs
