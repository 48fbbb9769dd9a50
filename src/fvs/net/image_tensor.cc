#include "fvs/net/image_tensor.h"

#include <cstring>

namespace fvs {

torch::Tensor ImageToTensor(const Image& image) {
  return torch::from_blob(const_cast<float*>(image.data.data()),
                          {image.height, image.width, image.channels}, torch::kFloat32)
      .permute({2, 0, 1})
      .unsqueeze(0)
      .contiguous();
}

Image TensorToImage(const torch::Tensor& chw) {
  const torch::Tensor hwc = (chw.dim() == 4 ? chw.squeeze(0) : chw)
                                .to(torch::kCPU, torch::kFloat32)
                                .permute({1, 2, 0})
                                .contiguous();
  Image image(static_cast<int>(hwc.size(1)), static_cast<int>(hwc.size(0)),
              static_cast<int>(hwc.size(2)));
  std::memcpy(image.data.data(), hwc.data_ptr<float>(),
              image.data.size() * sizeof(float));
  return image;
}

}  // namespace fvs
