// Image-quality metrics of the evaluation protocol: PSNR and SSIM on [0, 1] images.
// SSIM is Wang et al. 2004 exactly: 11x11 Gaussian window (sigma 1.5, normalised),
// K1 = 0.01, K2 = 0.03, data range 1, population (not sample) covariances, statistics over
// the 'valid' region only (windows entirely inside the image), mean over pixels, then over
// channels. This matches scikit-image's structural_similarity(gaussian_weights=True,
// sigma=1.5, use_sample_covariance=False, data_range=1) and the reference MATLAB code.
// Predictions are quantised to 8 bits first (QuantizeTo8Bit), as the paper's protocol.
#pragma once

#include "fvs/util/image.h"

namespace fvs::eval {

// Rounds every value to the nearest of 0, 1/255, ..., 1 (clamped), as saving a PNG would.
Image QuantizeTo8Bit(const Image& image);

// Mean squared error over all pixels and channels (or only where mask > 0.5; the mask has 1
// channel and the images' size). Throws fvs::Error if sizes differ or the mask is empty.
double MeanSquaredError(const Image& a, const Image& b, const Image* mask = nullptr);

// 10 log10(1 / MSE); identical images give +infinity, reported as kMaxPsnr.
constexpr double kMaxPsnr = 100.0;
double Psnr(const Image& a, const Image& b, const Image* mask = nullptr);

// Mean SSIM. With a mask, only windows whose centre lies where mask > 0.5 count.
// Images smaller than 11x11 throw fvs::Error.
double Ssim(const Image& a, const Image& b, const Image* mask = nullptr);

}  // namespace fvs::eval
