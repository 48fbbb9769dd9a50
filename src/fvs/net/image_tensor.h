// Between the pipeline's images ([H,W,C] float, util/image.h) and LibTorch's [1,C,H,W]
// tensors: one conversion for the renderer, the trainer and LPIPS.
#pragma once

#include <torch/torch.h>

#include "fvs/util/image.h"

namespace fvs {

// [H,W,C] float image -> [1,C,H,W] float tensor on the CPU (a copy).
torch::Tensor ImageToTensor(const Image& image);
// [1,C,H,W] or [C,H,W] tensor of any device and real or bool dtype -> [H,W,C] float image
// (a copy).
Image TensorToImage(const torch::Tensor& chw);

}  // namespace fvs
