#include "fvs/train/loss.h"

#include <cmath>
#include <cstring>

#include "fvs/util/error.h"
#include "fvs/util/safetensors.h"

namespace fvs {
namespace {

torch::Tensor GaussianWindow(int size, double sigma,
                             const torch::TensorOptions& options) {
  const torch::Tensor x = torch::arange(size, torch::kDouble) - (size - 1) / 2.0;
  torch::Tensor g = torch::exp(-(x * x) / (2 * sigma * sigma));
  g = g / g.sum();
  return torch::outer(g, g).to(options);
}

// torchvision vgg19().features: conv indices and channels up to conv5_2; taps after the
// ReLUs of conv1_2, conv2_2, conv3_2, conv4_2, conv5_2.
struct VggConv {
  int index, in, out;
  bool pool_before;  // a 2x2 max-pool precedes it
  bool tap;          // its ReLU output is a perceptual feature
};
const VggConv kVgg[] = {
    {0, 3, 64, false, false},     {2, 64, 64, false, true},     // block 1
    {5, 64, 128, true, false},    {7, 128, 128, false, true},   // block 2
    {10, 128, 256, true, false},  {12, 256, 256, false, true},  // block 3 (3_1, 3_2)
    {14, 256, 256, false, false}, {16, 256, 256, false, false},
    {19, 256, 512, true, false},  {21, 512, 512, false, true},  // block 4 (4_1, 4_2)
    {23, 512, 512, false, false}, {25, 512, 512, false, false},
    {28, 512, 512, true, false},  {30, 512, 512, false, true},  // block 5 (5_1, 5_2)
};
const double kTapWeights[] = {1.0, 0.75, 0.5, 0.5, 1.0};

}  // namespace

torch::Tensor Ssim(const torch::Tensor& a, const torch::Tensor& b) {
  Require(a.sizes() == b.sizes() && a.dim() == 4 && a.size(2) >= 11 && a.size(3) >= 11,
          "ssim", "images must match and be at least 11x11");
  const int64_t c = a.size(1);
  const torch::Tensor w =
      GaussianWindow(11, 1.5, a.options()).expand({c, 1, 11, 11}).contiguous();
  auto filter = [&](const torch::Tensor& x) {
    return torch::nn::functional::conv2d(
        x, w, torch::nn::functional::Conv2dFuncOptions().groups(c));
  };
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  const torch::Tensor mu_a = filter(a), mu_b = filter(b);
  const torch::Tensor saa = filter(a * a) - mu_a * mu_a;
  const torch::Tensor sbb = filter(b * b) - mu_b * mu_b;
  const torch::Tensor sab = filter(a * b) - mu_a * mu_b;
  const torch::Tensor map = ((2 * mu_a * mu_b + c1) * (2 * sab + c2)) /
                            ((mu_a * mu_a + mu_b * mu_b + c1) * (saa + sbb + c2));
  return map.mean();
}

Vgg19FeaturesImpl::Vgg19FeaturesImpl() {
  for (const VggConv& c : kVgg) {
    convs_.push_back(register_module(
        "features_" + std::to_string(c.index),
        torch::nn::Conv2d(torch::nn::Conv2dOptions(c.in, c.out, 3).padding(1))));
  }
  for (auto& p : parameters()) p.set_requires_grad(false);
}

std::vector<std::pair<std::string, std::vector<int64_t>>>
Vgg19FeaturesImpl::ExpectedTensors() {
  std::vector<std::pair<std::string, std::vector<int64_t>>> out;
  for (const VggConv& c : kVgg) {
    const std::string base = "features." + std::to_string(c.index);
    out.push_back({base + ".weight", {c.out, c.in, 3, 3}});
    out.push_back({base + ".bias", {c.out}});
  }
  return out;
}

void Vgg19FeaturesImpl::Load(const std::string& path) {
  const SafeTensorsFile file = ReadSafeTensors(path);
  std::vector<std::string> problems;
  torch::NoGradGuard no_grad;
  size_t n = 0;
  for (const auto& [name, shape] : ExpectedTensors()) {
    torch::nn::Conv2d& conv = convs_[n / 2];
    torch::Tensor& dest = (n % 2 == 0) ? conv->weight : conv->bias;
    ++n;
    const SafeTensor* t = file.Find(name);
    if (!t) t = file.Find(name.substr(std::strlen("features.")));
    if (!t) {
      problems.push_back("missing " + name);
      continue;
    }
    if (t->shape != shape) {
      problems.push_back("wrong shape of " + name);
      continue;
    }
    std::vector<float> values;
    try {
      values = t->ToFloats();
    } catch (const Error&) {
      problems.push_back(name + " is not floating point");
      continue;
    }
    const torch::Tensor src = torch::from_blob(values.data(), shape, torch::kFloat);
    if (!torch::isfinite(src).all().item<bool>()) {
      problems.push_back(name + " holds NaN or Inf");
      continue;
    }
    dest.copy_(src);
  }
  if (!problems.empty()) {
    std::string list;
    for (size_t i = 0; i < problems.size() && i < 6; ++i)
      list += (i ? ", " : "") + problems[i];
    if (problems.size() > 6)
      list += ", ... (" + std::to_string(problems.size()) + " in all)";
    throw Error(path, "not torchvision VGG19 features weights: " + list);
  }
}

std::vector<torch::Tensor> Vgg19FeaturesImpl::forward(const torch::Tensor& images01) {
  const auto opts = images01.options();
  const torch::Tensor mean =
      torch::tensor({0.485, 0.456, 0.406}, opts).reshape({1, 3, 1, 1});
  const torch::Tensor stdev =
      torch::tensor({0.229, 0.224, 0.225}, opts).reshape({1, 3, 1, 1});
  torch::Tensor x = (images01 - mean) / stdev;
  std::vector<torch::Tensor> taps;
  for (size_t i = 0; i < convs_.size(); ++i) {
    if (kVgg[i].pool_before) x = torch::max_pool2d(x, 2);
    x = torch::relu(convs_[i]->forward(x));
    if (kVgg[i].tap) taps.push_back(x);
  }
  return taps;
}

bool LossUsesLpips(const std::string& kind) {
  return kind == "l1+lpips" || kind == "l1+ssim+lpips";
}

std::string ChooseLoss(const std::string& requested, bool have_vgg19, bool have_lpips) {
  if (requested == "auto") {
    return have_vgg19 ? "l1+vgg19" : have_lpips ? "l1+lpips" : "l1+ssim";
  }
  Require(requested != "l1+vgg19" || have_vgg19, "--Train.loss",
          "l1+vgg19 needs --vgg19_path");
  Require(!LossUsesLpips(requested) || have_lpips, "--Train.loss",
          requested + " needs LPIPS weights (--lpips_path or " + kLpipsPathEnv + ")");
  return requested;
}

TrainingLoss::TrainingLoss(const LossOptions& options, const torch::Device& device)
    : options_(options) {
  const std::string& kind = options_.kind;
  Require(kind == "l1+ssim" || LossUsesLpips(kind) || kind == "l1+vgg19", "TrainingLoss",
          "unknown loss '" + kind + "'");
  if (kind == "l1+vgg19") {
    vgg_ = Vgg19Features();
    vgg_->Load(options_.vgg19_path);
    vgg_->to(device);
    vgg_->eval();
  }
  if (LossUsesLpips(kind)) {
    Require(!options_.lpips.is_empty(), "TrainingLoss", kind + " without LPIPS weights");
    options_.lpips->to(device);
    options_.lpips->eval();
  } else {
    options_.lpips = nullptr;  // validation may hold it; the loss does not need it
  }
}

std::string TrainingLoss::SecondTermName() const {
  if (Name() == "l1+ssim+lpips") return "1-ssim+lpips";
  return Name() == "l1+lpips" ? "lpips" : Name() == "l1+vgg19" ? "vgg" : "1-ssim";
}

torch::Tensor TrainingLoss::SecondTerm(const torch::Tensor& prediction01,
                                       const torch::Tensor& target01) {
  if (LossUsesLpips(Name())) {
    torch::Tensor second =
        options_.lpips_weight * options_.lpips->forward(prediction01, target01).mean();
    // SSIM beside LPIPS: LPIPS alone buys texture at the price of structure (fvs_agg on
    // the validation scenes: LPIPS -0.011, SSIM -0.043 against ulr after 250 steps).
    if (Name() == "l1+ssim+lpips") second = second + (1.0 - Ssim(prediction01, target01));
    return second;
  }
  if (Name() == "l1+vgg19") {
    const auto fp = vgg_->forward(prediction01);
    const auto ft = vgg_->forward(target01);
    torch::Tensor second = torch::zeros({}, prediction01.options());
    for (size_t i = 0; i < fp.size(); ++i) {
      second = second + kTapWeights[i] * (fp[i] - ft[i].detach()).abs().mean();
    }
    return second;
  }
  return 1.0 - Ssim(prediction01, target01);
}

torch::Tensor ChoiceLoss(const torch::Tensor& weights,
                         const torch::Tensor& per_source_rgb,
                         const torch::Tensor& target01, const torch::Tensor& seen) {
  const torch::Tensor error =
      ((per_source_rgb.to(torch::kFloat32) + 1.0) * 0.5 - target01).abs().mean(1, true);
  const torch::Tensor expected = (weights.to(torch::kFloat32) * error).sum(0, true);
  const torch::Tensor mask = (seen > 0).to(torch::kFloat32);
  return (expected * mask).sum() / mask.sum().clamp_min(1.0);
}

LossValue TrainingLoss::operator()(const torch::Tensor& prediction01,
                                   const torch::Tensor& target01) {
  LossValue out;
  const torch::Tensor l1 = (prediction01 - target01).abs().mean();
  const torch::Tensor second = SecondTerm(prediction01, target01);
  out.total = l1 + second;
  out.l1 = l1.item<double>();
  out.second = second.item<double>();
  return out;
}

}  // namespace fvs
