#include "fvs/net/lpips_net.h"

#include <algorithm>

#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"

namespace fvs {
namespace {

// One tensor of the file with the expected shape, or an undefined tensor after adding
// the reason to *problems (all problems are reported together).
torch::Tensor TakeTensor(const SafeTensorsFile& file, const std::string& name,
                         const std::vector<int64_t>& shape, std::string* problems) {
  auto problem = [&](const std::string& what) {
    *problems += (problems->empty() ? "" : ", ") + name + " " + what;
    return torch::Tensor();
  };
  const SafeTensor* t = file.Find(name);
  if (!t) return problem("missing");
  if (t->shape != shape) return problem("has the wrong shape");
  std::vector<float> values;
  try {
    values = t->ToFloats();
  } catch (const Error&) {
    return problem("is not floating point");
  }
  torch::Tensor v = torch::from_blob(values.data(), shape, torch::kFloat32).clone();
  if (!torch::isfinite(v).all().item<bool>()) return problem("is not finite");
  return v;
}

// Unit length over channels. The sqrt's argument gets eps^2 so that its gradient stays
// finite where every channel is 0 (a dead ReLU location; the plain form gives NaN
// there); the value differs from the package's only below ~1e-27.
torch::Tensor NormalizeChannels(const torch::Tensor& x) {
  const double eps = 1e-10;
  return x / ((x.pow(2).sum(1, true) + eps * eps).sqrt() + eps);
}

}  // namespace

LpipsNetImpl::LpipsNetImpl(const std::string& path) {
  const SafeTensorsFile file = ReadSafeTensors(path);
  network_ = file.Find("features.28.weight") ? "vgg" : "alex";
  layout_ = LpipsLayout(network_);
  std::string problems;
  const auto expected = LpipsExpectedTensors(network_);
  for (size_t i = 0; i < expected.size(); ++i) {
    const auto& [name, shape] = expected[i];
    const torch::Tensor t = TakeTensor(file, name, shape, &problems);
    // Buffers, not parameters: they move with .to(device) but no optimiser sees them.
    // (Module names may not hold dots.)
    std::string key = name;
    std::replace(key.begin(), key.end(), '.', '_');
    const torch::Tensor b = register_buffer(key, t.defined() ? t : torch::zeros(shape));
    if (i < 2 * layout_.size()) {
      (i % 2 == 0 ? weights_ : biases_).push_back(b);
    } else {
      lins_.push_back(b);
    }
  }
  Require(problems.empty(), path,
          "not LPIPS " + network_ + " weights (" + problems + "; see doc/evaluation.md)");
}

std::vector<torch::Tensor> LpipsNetImpl::Features(const torch::Tensor& images01) {
  const auto options = images01.options();
  const torch::Tensor shift = torch::tensor({-.030f, -.088f, -.188f}, options);
  const torch::Tensor scale = torch::tensor({.458f, .448f, .450f}, options);
  torch::Tensor x =
      ((2 * images01 - 1) - shift.view({1, 3, 1, 1})) / scale.view({1, 3, 1, 1});
  std::vector<torch::Tensor> taps;
  for (size_t i = 0; i < layout_.size(); ++i) {
    const LpipsConv& c = layout_[i];
    if (c.pool_before) {
      x = network_ == "alex" ? torch::max_pool2d(x, 3, 2) : torch::max_pool2d(x, 2, 2);
    }
    x = torch::relu(torch::conv2d(x, weights_[i], biases_[i], c.stride, c.padding));
    if (c.tap) taps.push_back(x);
  }
  return taps;
}

torch::Tensor LpipsNetImpl::forward(const torch::Tensor& a, const torch::Tensor& b) {
  Require(a.dim() == 4 && a.size(1) == 3 && a.sizes() == b.sizes(), "LPIPS",
          "needs two RGB batches [B,3,H,W] of one size");
  torch::Tensor pa = a, pb = b;
  const int64_t min_side = LpipsMinimumSize(network_);
  const int64_t pad_h = std::max<int64_t>(0, min_side - a.size(2));
  const int64_t pad_w = std::max<int64_t>(0, min_side - a.size(3));
  if (pad_h > 0 || pad_w > 0) {
    namespace F = torch::nn::functional;
    const auto pad =
        F::PadFuncOptions({pad_w / 2, pad_w - pad_w / 2, pad_h / 2, pad_h - pad_h / 2})
            .mode(torch::kReplicate);
    pa = F::pad(a, pad);
    pb = F::pad(b, pad);
  }
  const std::vector<torch::Tensor> fa = Features(pa), fb = Features(pb);
  torch::Tensor total = torch::zeros({a.size(0)}, a.options());
  for (size_t k = 0; k < fa.size(); ++k) {
    const torch::Tensor d = (NormalizeChannels(fa[k]) - NormalizeChannels(fb[k])).pow(2);
    total = total + torch::conv2d(d, lins_[k]).mean({1, 2, 3});
  }
  return total;
}

}  // namespace fvs
