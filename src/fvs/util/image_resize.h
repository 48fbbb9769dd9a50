// Resampling and box filtering of float images.
#pragma once

#include <utility>

#include "fvs/util/image.h"

namespace fvs {

// Area-weighted resampling (box filter of the exact pixel footprint): the right filter
// for the 4x reduction of training images and the small photos the backdrop fit
// compares; also works for enlargements (nearest).
Image ResizeArea(const Image& image, int width, int height);

// Width and height of an image scaled so that its longest side is at most `max_side`
// (never enlarged), each rounded and at least `min_side`: the working size of every
// stage that compares photos at a bounded size (stereo, mesh refinement, face
// consistency, the backdrop, photo quality).
std::pair<int, int> ScaledSize(int width, int height, int max_side, int min_side = 1);

// The mean over the (2 radius + 1)^2 window around each pixel, of the window's pixels
// inside the image (no padding counted), per channel; radius 0: the image. Each pass adds
// a variance of radius (radius + 1) / 3 per axis, so a few passes approach a Gaussian
// (three: sigma about radius); blurred photos for the photo-quality tests and benchmark.
Image BoxBlur(const Image& image, int radius);

}  // namespace fvs
