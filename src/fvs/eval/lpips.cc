#include "fvs/eval/lpips.h"

#include <torch/torch.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>

#include "fvs/net/image_tensor.h"
#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"

namespace fvs::eval {
namespace {

// One conv of a torchvision `features` stack: its index, channels, kernel, stride,
// padding, whether a max pool (3x3 stride 2 for AlexNet, 2x2 for VGG) comes before it,
// and whether an LPIPS layer is tapped after its ReLU.
struct ConvSpec {
  int index, in, out, kernel, stride, padding;
  bool pool_before, tap;
};

std::vector<ConvSpec> Layout(const std::string& network) {
  if (network == "alex") {
    return {{0, 3, 64, 11, 4, 2, false, true},
            {3, 64, 192, 5, 1, 2, true, true},
            {6, 192, 384, 3, 1, 1, true, true},
            {8, 384, 256, 3, 1, 1, false, true},
            {10, 256, 256, 3, 1, 1, false, true}};
  }
  return {{0, 3, 64, 3, 1, 1, false, false},     {2, 64, 64, 3, 1, 1, false, true},
          {5, 64, 128, 3, 1, 1, true, false},    {7, 128, 128, 3, 1, 1, false, true},
          {10, 128, 256, 3, 1, 1, true, false},  {12, 256, 256, 3, 1, 1, false, false},
          {14, 256, 256, 3, 1, 1, false, true},  {17, 256, 512, 3, 1, 1, true, false},
          {19, 512, 512, 3, 1, 1, false, false}, {21, 512, 512, 3, 1, 1, false, true},
          {24, 512, 512, 3, 1, 1, true, false},  {26, 512, 512, 3, 1, 1, false, false},
          {28, 512, 512, 3, 1, 1, false, true}};
}

std::vector<int> TapChannels(const std::string& network) {
  std::vector<int> channels;
  for (const ConvSpec& c : Layout(network)) {
    if (c.tap) channels.push_back(c.out);
  }
  return channels;
}

torch::Tensor ToTensor(const SafeTensor& t) {
  const std::vector<float> values = t.ToFloats();
  return torch::from_blob(const_cast<float*>(values.data()), t.shape, torch::kFloat32)
      .clone();
}

class Lpips {
 public:
  Lpips(const SafeTensorsFile& file, const std::string& path) {
    network_ = file.Find("features.28.weight") ? "vgg" : "alex";
    layout_ = Layout(network_);
    std::string problems;
    auto take = [&](const std::string& name, const std::vector<int64_t>& shape) {
      const SafeTensor* t = file.Find(name);
      if (!t) {
        problems += (problems.empty() ? "" : ", ") + name + " missing";
        return torch::Tensor();
      }
      if (t->shape != shape) {
        problems += (problems.empty() ? "" : ", ") + name + " has the wrong shape";
        return torch::Tensor();
      }
      torch::Tensor v = ToTensor(*t);
      if (!torch::isfinite(v).all().item<bool>()) {
        problems += (problems.empty() ? "" : ", ") + name + " is not finite";
      }
      return v;
    };
    for (const auto& [name, shape] : LpipsExpectedTensors(network_)) {
      tensors_.push_back(take(name, shape));
    }
    Require(
        problems.empty(), path,
        "not LPIPS " + network_ + " weights (" + problems + "; see doc/evaluation.md)");
  }

  const std::string& network() const { return network_; }

  double Distance(const Image& a, const Image& b) {
    torch::NoGradGuard no_grad;
    const std::vector<torch::Tensor> fa = Features(a), fb = Features(b);
    double total = 0;
    for (size_t k = 0; k < fa.size(); ++k) {
      const torch::Tensor& lin = tensors_[2 * layout_.size() + k];
      const torch::Tensor d = (Normalize(fa[k]) - Normalize(fb[k])).pow(2);
      total += torch::conv2d(d, lin).mean().item<double>();
    }
    Require(std::isfinite(total), "LPIPS", "distance is not finite");
    return total;
  }

 private:
  static torch::Tensor Normalize(const torch::Tensor& x) {
    return x / (x.pow(2).sum(1, true).sqrt() + 1e-10);
  }

  std::vector<torch::Tensor> Features(const Image& image) {
    Require(image.channels == 3, "LPIPS", "needs RGB images");
    torch::Tensor x = ImageToTensor(image);
    const torch::Tensor shift =
        torch::tensor({-.030f, -.088f, -.188f}).view({1, 3, 1, 1});
    const torch::Tensor scale = torch::tensor({.458f, .448f, .450f}).view({1, 3, 1, 1});
    x = ((2 * x - 1) - shift) / scale;
    std::vector<torch::Tensor> taps;
    for (size_t i = 0; i < layout_.size(); ++i) {
      const ConvSpec& c = layout_[i];
      if (c.pool_before) {
        x = network_ == "alex" ? torch::max_pool2d(x, 3, 2) : torch::max_pool2d(x, 2, 2);
      }
      x = torch::relu(
          torch::conv2d(x, tensors_[2 * i], tensors_[2 * i + 1], c.stride, c.padding));
      if (c.tap) taps.push_back(x);
    }
    return taps;
  }

  std::string network_;
  std::vector<ConvSpec> layout_;
  std::vector<torch::Tensor> tensors_;  // weight, bias per conv; then lin0..lin4
};

}  // namespace

std::vector<std::pair<std::string, std::vector<int64_t>>> LpipsExpectedTensors(
    const std::string& network) {
  Require(network == "alex" || network == "vgg", "LPIPS",
          "network must be alex or vgg, not '" + network + "'");
  std::vector<std::pair<std::string, std::vector<int64_t>>> names;
  for (const ConvSpec& c : Layout(network)) {
    const std::string prefix = "features." + std::to_string(c.index);
    names.push_back({prefix + ".weight", {c.out, c.in, c.kernel, c.kernel}});
    names.push_back({prefix + ".bias", {c.out}});
  }
  const std::vector<int> channels = TapChannels(network);
  for (size_t k = 0; k < channels.size(); ++k) {
    names.push_back(
        {"lin" + std::to_string(k) + ".model.1.weight", {1, channels[k], 1, 1}});
  }
  return names;
}

PerceptualDistance LoadLpips(const std::string& path, std::string* why_not,
                             std::string* network) {
  why_not->clear();
  if (path.empty()) {
    *why_not = "LPIPS: not available (no --lpips_path given)";
    return {};
  }
  try {
    Require(std::filesystem::is_regular_file(path), path, "no such file");
    ConfigureTorchThreads();
    auto lpips = std::make_shared<Lpips>(ReadSafeTensors(path), path);
    if (network) *network = lpips->network();
    auto mutex = std::make_shared<std::mutex>();
    return [lpips, mutex](const Image& a, const Image& b) {
      std::lock_guard<std::mutex> lock(*mutex);
      return lpips->Distance(a, b);
    };
  } catch (const std::exception& e) {
    *why_not = std::string("LPIPS: not available: ") + e.what();
    return {};
  }
}

}  // namespace fvs::eval
