#include "fvs/net/aggregate.h"

#include <cmath>

#include "fvs/net/ulr_weights.h"

namespace fvs {
namespace F = torch::nn::functional;
namespace {

// Zero padding on the right and bottom to even sizes (one 2x down-sampling inside).
torch::Tensor PadEven(const torch::Tensor& x) {
  const int64_t ph = x.size(2) % 2, pw = x.size(3) % 2;
  if (ph == 0 && pw == 0) return x;
  return F::pad(x, F::PadFuncOptions({0, pw, 0, ph}));
}

torch::Tensor CropTo(const torch::Tensor& x, int64_t height, int64_t width) {
  if (x.size(2) == height && x.size(3) == width) return x;
  return x.narrow(2, 0, height).narrow(3, 0, width);
}

// Bilinear: a nearest-neighbour 2x up-sampling mixed in by 1x1 convs leaves 2x2 blocks in
// flat areas, which SSIM punishes on dark backdrops.
torch::Tensor Up2(const torch::Tensor& x) {
  return F::interpolate(x, F::InterpolateFuncOptions()
                               .scale_factor(std::vector<double>{2.0, 2.0})
                               .mode(torch::kBilinear)
                               .align_corners(false));
}

torch::Tensor Down2(const torch::Tensor& x) {
  return F::avg_pool2d(x, F::AvgPool2dFuncOptions(2));
}

// Context at half resolution (down1, down2), up-sampled and mixed back into x at full
// resolution (1x1 mix, then one 3x3: alignment is a matter of pixels). x has even sizes.
torch::Tensor WithHalfResolutionContext(const torch::Tensor& x, ConvUnit& down1,
                                        ConvUnit& down2, ConvUnit& mix,
                                        ConvUnit& context) {
  const torch::Tensor d = torch::relu(down2(torch::relu(down1(Down2(x)))));
  return torch::relu(context(torch::relu(mix(torch::cat({x, Up2(d)}, 1)))));
}

void ZeroInit(ConvUnit& unit) {
  torch::NoGradGuard no_grad;
  for (auto& p : unit->parameters()) p.zero_();
}

}  // namespace

AggregateBlenderImpl::AggregateBlenderImpl(const ModelConfig& config)
    : ulr_prior_(config.ulr_prior) {
  const int w0 = config.blend_channels[0], w1 = config.blend_channels[1];
  auto* s = &source_;
  s_in_ = Add("agg_s_in", kSourceInputs, w0, 1, 0, s);
  s_down1_ = Add("agg_s_down1", w0, w1, 3, 1, s);
  s_down2_ = Add("agg_s_down2", w1, w1, 3, 1, s);
  s_mix_ = Add("agg_s_mix", w0 + w1, w0, 1, 0, s);
  s_context_ = Add("agg_s_context", w0, w0, 3, 0, s);
  s_pool_ = Add("agg_s_pool", 3 * w0, w0, 1, 0, s);
  confidence_ = Add("agg_confidence", w0, 1, 1, 0, s);
  correction_ = Add("agg_correction", w0, 3, 1, 0, s);
  auto* t = &target_;
  r_in_ = Add("agg_r_in", kRefinerInputs, w0, 3, 0, t);
  r_down1_ = Add("agg_r_down1", w0, w1, 3, 1, t);
  r_down2_ = Add("agg_r_down2", w1, w1, 3, 1, t);
  r_mix_ = Add("agg_r_mix", w0 + w1, w0, 1, 0, t);
  r_context_ = Add("agg_r_context", w0, w0, 3, 0, t);
  r_out_ = Add("agg_r_out", w0, 3, 1, 0, t);
  // Zero heads and residual: the untrained network is the ULR blend.
  ZeroInit(confidence_);
  ZeroInit(correction_);
  ZeroInit(r_out_);
}

ConvUnit AggregateBlenderImpl::Add(const std::string& name, int in, int out, int kernel,
                                   int level, std::vector<ConvUnit>* list) {
  ConvUnit unit = register_module(name, ConvUnit(in, out, kernel, false, level));
  list->push_back(unit);
  return unit;
}

BlendOutput AggregateBlenderImpl::forward(const torch::Tensor& warped,
                                          const torch::Tensor& valid_depth,
                                          const torch::Tensor& valid_warp,
                                          const torch::Tensor& ulr_log_weights) {
  const int64_t k = warped.size(0), height = warped.size(2), width = warped.size(3);
  const auto opts = warped.options();
  const torch::Tensor v = valid_warp.to(opts);
  const torch::Tensor vd = valid_depth.to(opts);
  const torch::Tensor ulr_log = ulr_log_weights.to(opts);
  // Colours the blend offers: black where the source does not see the pixel (as `ulr`).
  const torch::Tensor offered =
      torch::where(v > 0.5, warped, torch::full_like(warped, -1));
  const torch::Tensor colour = warped * v;
  const torch::Tensor ulr_weights = SoftmaxWeights(ulr_prior_ * ulr_log);
  const torch::Tensor ulr = (ulr_weights * offered).sum(0, true);  // [1,3,H,W]
  const torch::Tensor seeing = v.sum(0, true);                     // [1,1,H,W]
  const torch::Tensor count = seeing.clamp_min(1.0);
  const torch::Tensor mean = colour.sum(0, true) / count;
  const torch::Tensor variance = ((colour - mean).pow(2) * v).sum(0, true) / count;
  const torch::Tensor deviation = (variance + 1e-6).sqrt();
  const torch::Tensor share = seeing / static_cast<double>(k);
  auto per_source = [&](const torch::Tensor& x) { return x.expand({k, -1, -1, -1}); };

  // Per-source stack; log-weights scaled so that the floor (-9.2) is about -1.
  const double log_floor = -std::log(kUlrWeightFloor);
  const torch::Tensor difference = (warped - ulr) * v;
  const std::vector<torch::Tensor> inputs = {colour,
                                             v,
                                             ulr_log / log_floor,
                                             ulr_weights,
                                             difference,
                                             per_source(ulr),
                                             per_source(deviation),
                                             per_source(vd),
                                             per_source(share)};
  torch::Tensor x = torch::cat(inputs, 1);
  x = PadEven(x);
  torch::Tensor h = WithHalfResolutionContext(torch::relu(s_in_(x)), s_down1_, s_down2_,
                                              s_mix_, s_context_);
  // Across sources: mean and max of the seeing sources' states, given to every source.
  const torch::Tensor vp = PadEven(v);
  // Clamped after padding: a 0/0 in the padding would be cropped from the output but
  // not from the weights' gradients.
  const torch::Tensor pooled_mean =
      (h * vp).sum(0, true) / PadEven(seeing).clamp_min(1.0);
  const torch::Tensor pooled_max = std::get<0>((h * vp).max(0, true));
  h = torch::relu(
      s_pool_(torch::cat({h, per_source(pooled_mean), per_source(pooled_max)}, 1)));
  h = CropTo(h, height, width);

  BlendOutput out;
  out.per_source_rgb = offered + correction_(h);
  out.weights = SoftmaxWeights(confidence_(h) + ulr_prior_ * ulr_log);
  const torch::Tensor blend = (out.weights * out.per_source_rgb).sum(0, true);

  // Refiner: a residual on the blended image.
  torch::Tensor r = PadEven(torch::cat({blend, ulr, deviation, vd, share}, 1));
  r = WithHalfResolutionContext(torch::relu(r_in_(r)), r_down1_, r_down2_, r_mix_,
                                r_context_);
  out.rgb = blend + CropTo(r_out_(r), height, width);
  return out;
}

std::vector<const ConvUnitImpl*> AggregateBlenderImpl::PerSourceUnits() const {
  std::vector<const ConvUnitImpl*> units;
  for (const ConvUnit& u : source_) units.push_back(u.get());
  return units;
}

std::vector<const ConvUnitImpl*> AggregateBlenderImpl::PerTargetUnits() const {
  std::vector<const ConvUnitImpl*> units;
  for (const ConvUnit& u : target_) units.push_back(u.get());
  return units;
}

}  // namespace fvs
