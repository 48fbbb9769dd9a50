#include "fvs/net/net.h"

#include <algorithm>

#include "fvs/net/aggregate.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {
namespace F = torch::nn::functional;
namespace {

const char kSubject[] = "FvsNet";

std::string Shape(const torch::Tensor& t) {
  if (!t.defined()) return "(undefined)";
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? "," : "") + std::to_string(t.size(i));
  return s + "]";
}

int64_t RoundUp(int64_t value, int64_t multiple) {
  return (value + multiple - 1) / multiple * multiple;
}

// Pads [N,C,H,W] on the right and bottom to multiples of `stride`.
torch::Tensor PadTo(const torch::Tensor& x, int64_t stride, bool replicate) {
  const int64_t ph = RoundUp(x.size(2), stride) - x.size(2);
  const int64_t pw = RoundUp(x.size(3), stride) - x.size(3);
  if (ph == 0 && pw == 0) return x;
  auto options = F::PadFuncOptions({0, pw, 0, ph});
  // Replicate for images (features at the border see plausible content), zeros for the
  // blending input (zero = "no source there", the same as an invalid warp).
  if (replicate) {
    options.mode(torch::kReplicate);
    // LibTorch 1.13's CPU replication pad has no bf16/fp16 kernel: pad in fp32.
    if (x.is_cpu() && x.scalar_type() != torch::kFloat32 &&
        x.scalar_type() != torch::kFloat64) {
      return F::pad(x.to(torch::kFloat32), options).to(x.scalar_type());
    }
  } else {
    options.mode(torch::kConstant);
  }
  return F::pad(x, options);
}

torch::Tensor Crop(const torch::Tensor& x, int64_t height, int64_t width) {
  if (x.size(2) == height && x.size(3) == width) return x;
  return x.narrow(2, 0, height).narrow(3, 0, width);
}

torch::Tensor UpsampleTo(const torch::Tensor& x, const torch::Tensor& like) {
  return F::interpolate(x, F::InterpolateFuncOptions()
                               .size(std::vector<int64_t>{like.size(2), like.size(3)})
                               .mode(torch::kNearest));
}

double FlopsAt(const std::vector<const ConvUnitImpl*>& units, int64_t height,
               int64_t width) {
  double flops = 0;
  for (const ConvUnitImpl* u : units) {
    const double pixels = static_cast<double>(height >> u->level()) *
                          static_cast<double>(width >> u->level());
    flops += 2.0 * static_cast<double>(u->MacsPerPixel()) * pixels;
  }
  return flops;
}

}  // namespace

void ConfigureTorchThreads() { torch::set_num_threads(DefaultNumThreads()); }

ConvUnitImpl::ConvUnitImpl(int in_channels, int out_channels, int kernel, bool separable,
                           int level)
    : in_(in_channels),
      out_(out_channels),
      kernel_(kernel),
      level_(level),
      separable_(separable && kernel > 1) {
  const int pad = kernel / 2;
  if (separable_) {
    depthwise_ = register_module(
        "dw", torch::nn::Conv2d(torch::nn::Conv2dOptions(in_, in_, kernel_)
                                    .padding(pad)
                                    .groups(in_)
                                    .bias(false)));
    pointwise_ =
        register_module("pw", torch::nn::Conv2d(torch::nn::Conv2dOptions(in_, out_, 1)));
  } else {
    conv_ = register_module(
        "conv",
        torch::nn::Conv2d(torch::nn::Conv2dOptions(in_, out_, kernel_).padding(pad)));
  }
}

torch::Tensor ConvUnitImpl::forward(const torch::Tensor& x) {
  return separable_ ? pointwise_(depthwise_(x)) : conv_(x);
}

int64_t ConvUnitImpl::MacsPerPixel() const {
  const int64_t k2 = static_cast<int64_t>(kernel_) * kernel_;
  return separable_ ? in_ * k2 + static_cast<int64_t>(in_) * out_
                    : static_cast<int64_t>(in_) * out_ * k2;
}

ConvGruImpl::ConvGruImpl(int in_channels, int hidden_channels, bool separable, int level)
    : hidden_(hidden_channels) {
  gates_ = register_module("gates", ConvUnit(in_channels + hidden_channels,
                                             2 * hidden_channels, 3, separable, level));
  candidate_ = register_module(
      "candidate",
      ConvUnit(in_channels + hidden_channels, hidden_channels, 3, separable, level));
}

torch::Tensor ConvGruImpl::forward(const torch::Tensor& x, const torch::Tensor& h_in) {
  const torch::Tensor h =
      h_in.defined()
          ? h_in
          : torch::zeros({x.size(0), hidden_, x.size(2), x.size(3)}, x.options());
  const std::vector<torch::Tensor> zr =
      torch::sigmoid(gates_(torch::cat({x, h}, 1))).chunk(2, 1);
  const torch::Tensor& z = zr[0];
  const torch::Tensor& r = zr[1];
  const torch::Tensor c = torch::relu(candidate_(torch::cat({x, r * h}, 1)));
  return (1 - z) * h + z * c;
}

std::vector<const ConvUnitImpl*> ConvGruImpl::Units() const {
  return {gates_.get(), candidate_.get()};
}

FvsNetImpl::FvsNetImpl(const ModelConfig& config) : config_(config) {
  config_.Check();
  if (config_.blender == "aggregate") {
    aggregate_ = register_module("aggregate", std::make_shared<AggregateBlenderImpl>(config_));
    for (const ConvUnitImpl* u : aggregate_->PerSourceUnits()) blend_units_.push_back(u);
    // Counted per source although it runs once per target (an upper bound for K > 1).
    for (const ConvUnitImpl* u : aggregate_->PerTargetUnits()) blend_units_.push_back(u);
    return;
  }
  const bool sep = config_.depthwise_separable;

  // Encoder: VGG-like down stages (average pooling between), U-Net decoder with two convs
  // per stage; the last stage outputs feature_channels at full resolution.
  const std::vector<int>& ec = config_.encoder_channels;
  const int stages = static_cast<int>(ec.size());
  int channels = 3;
  for (int s = 0; s < stages; ++s) {
    encoder_down_.emplace_back();
    for (int j = 0; j < config_.encoder_convs[s]; ++j) {
      ConvUnit unit =
          register_module("encoder_d" + std::to_string(s) + "_" + std::to_string(j),
                          ConvUnit(channels, ec[s], 3, sep && channels > 3, s));
      encoder_down_.back().push_back(unit);
      encoder_units_.push_back(unit.get());
      channels = ec[s];
    }
  }
  for (int s = stages - 2; s >= 0; --s) {
    const int out = s == 0 ? config_.feature_channels : ec[s];
    encoder_up_.emplace_back();
    for (int j = 0; j < 2; ++j) {
      const int in = j == 0 ? channels + ec[s] : out;
      ConvUnit unit =
          register_module("encoder_u" + std::to_string(s) + "_" + std::to_string(j),
                          ConvUnit(in, out, 3, sep, s));
      encoder_up_.back().push_back(unit);
      encoder_units_.push_back(unit.get());
      channels = out;
    }
  }

  // Blending U-Net: stages down 0..L-1 then up L-2..0, each ending in a ConvGRU (or a
  // plain conv without recurrence).
  const std::vector<int>& bc = config_.blend_channels;
  const int levels = static_cast<int>(bc.size());
  std::vector<int> stage_levels;
  for (int l = 0; l < levels; ++l) stage_levels.push_back(l);
  for (int l = levels - 2; l >= 0; --l) stage_levels.push_back(l);
  channels = config_.BlendInputChannels();
  for (size_t i = 0; i < stage_levels.size(); ++i) {
    const int l = stage_levels[i];
    const bool up = static_cast<int>(i) >= levels;
    int in = up ? channels + bc[l] : channels;
    const std::string prefix =
        std::string("blend_") + (up ? "u" : "d") + std::to_string(l);
    Stage stage;
    const int plain = config_.blend_convs_per_stage - (config_.use_gru ? 1 : 0);
    for (int j = 0; j < plain; ++j) {
      ConvUnit unit = register_module(prefix + "_" + std::to_string(j),
                                      ConvUnit(in, bc[l], 3, sep, l));
      stage.convs.push_back(unit);
      blend_units_.push_back(unit.get());
      in = bc[l];
    }
    if (config_.use_gru) {
      stage.gru = register_module(prefix + "_gru", ConvGru(in, bc[l], sep, l));
      for (const ConvUnitImpl* u : stage.gru->Units()) blend_units_.push_back(u);
    }
    blend_stages_.push_back(stage);
    channels = bc[l];
  }
  rgb_head_ = register_module("rgb_head",
                              torch::nn::Conv2d(torch::nn::Conv2dOptions(bc[0], 3, 1)));
  if (config_.soft_argmax) {
    confidence_head_ = register_module(
        "confidence_head", torch::nn::Conv2d(torch::nn::Conv2dOptions(bc[0], 1, 1)));
  }
  if (config_.rgb_skip) {
    // Zero heads: every source first contributes its warped colour with equal confidence.
    torch::NoGradGuard no_grad;
    rgb_head_->weight.zero_();
    rgb_head_->bias.zero_();
    confidence_head_->weight.zero_();
    confidence_head_->bias.zero_();
  }
}

torch::Tensor FvsNetImpl::Encode(const torch::Tensor& images) {
  Require(images.dim() == 4 && images.size(1) == 3 && images.size(2) > 0 &&
              images.size(3) > 0,
          kSubject, "Encode expects images [K,3,H,W], got " + Shape(images));
  // No encoder: the blender works on the photos' own colours.
  if (config_.encoder_channels.empty()) return images;
  const int64_t height = images.size(2), width = images.size(3);
  torch::Tensor x = PadTo(images, config_.EncoderStride(), /*replicate=*/true);
  std::vector<torch::Tensor> skips;
  for (size_t s = 0; s < encoder_down_.size(); ++s) {
    if (s > 0) x = F::avg_pool2d(x, F::AvgPool2dFuncOptions(2));
    for (ConvUnit& unit : encoder_down_[s]) x = torch::relu(unit(x));
    skips.push_back(x);
  }
  for (size_t i = 0; i < encoder_up_.size(); ++i) {
    const torch::Tensor& skip = skips[skips.size() - 2 - i];
    x = torch::cat({UpsampleTo(x, skip), skip}, 1);
    for (ConvUnit& unit : encoder_up_[i]) x = torch::relu(unit(x));
  }
  if (config_.rgb_skip) return torch::cat({Crop(x, height, width), images}, 1);
  return Crop(x, height, width);
}

torch::Tensor FvsNetImpl::BlendPass(const torch::Tensor& input,
                                    std::vector<torch::Tensor>* state) {
  const int levels = static_cast<int>(config_.blend_channels.size());
  torch::Tensor x = input;
  std::vector<torch::Tensor> skips;
  for (size_t i = 0; i < blend_stages_.size(); ++i) {
    Stage& stage = blend_stages_[i];
    if (static_cast<int>(i) < levels) {
      if (i > 0) x = F::avg_pool2d(x, F::AvgPool2dFuncOptions(2));
    } else {
      const torch::Tensor& skip = skips[2 * (levels - 1) - i];
      x = torch::cat({UpsampleTo(x, skip), skip}, 1);
    }
    for (ConvUnit& unit : stage.convs) x = torch::relu(unit(x));
    if (stage.gru) {
      x = stage.gru(x, (*state)[i]);
      (*state)[i] = x;
    }
    if (static_cast<int>(i) < levels - 1) skips.push_back(x);
  }
  return x;
}

BlendOutput FvsNetImpl::Blend(const torch::Tensor& warped,
                              const torch::Tensor& valid_depth,
                              const torch::Tensor& valid_warp,
                              const torch::Tensor& ulr_log_weights) {
  Require(warped.dim() == 4 && warped.size(0) > 0 &&
              warped.size(1) == config_.EncodedChannels(),
          kSubject,
          "Blend expects warped features [K," +
              std::to_string(config_.EncodedChannels()) + ",H,W], got " + Shape(warped));
  const int64_t k = warped.size(0), height = warped.size(2), width = warped.size(3);
  if (config_.use_masks) {
    Require(valid_depth.defined() && valid_depth.dim() == 4 && valid_depth.size(0) == 1 &&
                valid_depth.size(1) == 1 && valid_depth.size(2) == height &&
                valid_depth.size(3) == width,
            kSubject,
            "Blend expects valid_depth [1,1," + std::to_string(height) + "," +
                std::to_string(width) + "], got " + Shape(valid_depth));
    Require(valid_warp.defined() && valid_warp.dim() == 4 && valid_warp.size(0) == k &&
                valid_warp.size(1) == 1 && valid_warp.size(2) == height &&
                valid_warp.size(3) == width,
            kSubject,
            "Blend expects valid_warp [" + std::to_string(k) + ",1," +
                std::to_string(height) + "," + std::to_string(width) + "], got " +
                Shape(valid_warp));
  }
  if (config_.ulr_prior > 0) {
    Require(ulr_log_weights.defined() && ulr_log_weights.dim() == 4 &&
                ulr_log_weights.size(0) == k && ulr_log_weights.size(1) == 1 &&
                ulr_log_weights.size(2) == height && ulr_log_weights.size(3) == width,
            kSubject,
            "Blend expects ULR log-weights [" + std::to_string(k) + ",1," +
                std::to_string(height) + "," + std::to_string(width) + "], got " +
                Shape(ulr_log_weights));
  }
  if (aggregate_) {
    BlendOutput out = aggregate_->forward(warped, valid_depth, valid_warp, ulr_log_weights);
    if (!is_training()) {
      out.rgb = torch::nan_to_num(out.rgb, 0.0, 1.0, -1.0).clamp(-1.0, 1.0);
    }
    return out;
  }
  // The input of sources [first, first + count): features + masks, padded. Built per
  // source in the recurrent case so that the full [K,66,H,W] never exists beside
  // `warped`.
  auto input = [&](int64_t first, int64_t count) {
    torch::Tensor x = warped.narrow(0, first, count);
    if (config_.use_masks) {
      x = torch::cat(
          {x, valid_depth.to(warped.options()).expand({count, 1, height, width}),
           valid_warp.narrow(0, first, count).to(warped.options())},
          1);
    }
    return PadTo(x, config_.BlendStride(), /*replicate=*/false);
  };

  // Recurrent: one source after the other, the 7 GRU states carried across; otherwise all
  // sources in one batch, independently. The heads run on each source's top state right
  // away so that only 4 channels per source are kept, not 64 (7 sources at 1080p would
  // otherwise hold 3.7 GB of top states).
  std::vector<torch::Tensor> rgbs, confidences;
  torch::Tensor last;  // the top state that has seen every source (fvs_single)
  auto heads = [&](const torch::Tensor& padded_top, int64_t first, int64_t count) {
    const torch::Tensor top = Crop(padded_top, height, width);
    if (config_.soft_argmax) {
      torch::Tensor rgb = rgb_head_(top);
      if (config_.rgb_skip) {
        torch::Tensor skip =
            warped.narrow(0, first, count).narrow(1, config_.feature_channels, 3);
        if (config_.use_masks) {
          // A source that does not see the pixel offers black, not what happens to lie
          // at its warped position (an occluder, or nothing): where no source sees a
          // pixel the untrained net renders black, as `ulr` does.
          const torch::Tensor seen =
              valid_warp.narrow(0, first, count).to(skip.options()) > 0.5;
          skip = torch::where(seen, skip, torch::full_like(skip, -1.0));
        }
        rgb = rgb + skip;
      }
      torch::Tensor confidence = confidence_head_(top);
      if (config_.mask_prior > 0) {
        confidence =
            confidence +
            config_.mask_prior *
                (valid_warp.narrow(0, first, count).to(confidence.options()) - 1);
      }
      if (config_.ulr_prior > 0) {
        confidence = confidence +
                     config_.ulr_prior *
                         ulr_log_weights.narrow(0, first, count).to(confidence.options());
      }
      rgbs.push_back(rgb);
      confidences.push_back(confidence);
    } else {
      // Without recurrence no state has seen every source: average the sources' states.
      last = config_.use_gru ? top : top.mean(0, /*keepdim=*/true);
    }
  };
  std::vector<torch::Tensor> state(blend_stages_.size());
  if (config_.use_gru) {
    for (int64_t i = 0; i < k; ++i) heads(BlendPass(input(i, 1), &state), i, 1);
  } else {
    heads(BlendPass(input(0, k), &state), 0, k);
  }

  BlendOutput out;
  if (config_.soft_argmax) {
    out.per_source_rgb = torch::cat(rgbs, 0);
    out.weights = SoftmaxWeights(torch::cat(confidences, 0));
    out.rgb = (out.weights * out.per_source_rgb).sum(0, /*keepdim=*/true);
  } else {
    out.rgb = rgb_head_(last);
  }
  if (!is_training()) {
    out.rgb = torch::nan_to_num(out.rgb, 0.0, 1.0, -1.0).clamp(-1.0, 1.0);
  }
  return out;
}

BlendOutput FvsNetImpl::Forward(const torch::Tensor& images, const torch::Tensor& grid,
                                const torch::Tensor& valid_depth,
                                const torch::Tensor& valid_warp,
                                const torch::Tensor& ulr_log_weights) {
  return Blend(WarpFeatures(Encode(images), grid), valid_depth, valid_warp,
               ulr_log_weights);
}

int64_t FvsNetImpl::EncoderParameterCount() const {
  int64_t n = 0;
  for (const auto& p : named_parameters()) {
    if (p.key().rfind("encoder_", 0) == 0) n += p.value().numel();
  }
  return n;
}

int64_t FvsNetImpl::BlenderParameterCount() const {
  int64_t n = 0;
  for (const auto& p : named_parameters()) {
    if (p.key().rfind("encoder_", 0) != 0) n += p.value().numel();
  }
  return n;
}

double FvsNetImpl::EncodeFlops(int height, int width) const {
  const int stride = config_.EncoderStride();
  return FlopsAt(encoder_units_, RoundUp(height, stride), RoundUp(width, stride));
}

double FvsNetImpl::BlendFlops(int height, int width) const {
  const int stride = config_.BlendStride();
  const int64_t ph = RoundUp(height, stride), pw = RoundUp(width, stride);
  if (aggregate_) return FlopsAt(blend_units_, ph, pw);
  const int heads = config_.soft_argmax ? 4 : 3;  // 1x1 convs: RGB (+ confidence)
  return FlopsAt(blend_units_, ph, pw) +
         2.0 * heads * config_.blend_channels[0] * static_cast<double>(height) * width;
}

torch::Tensor WarpFeatures(const torch::Tensor& features, const torch::Tensor& grid) {
  Require(features.dim() == 4, kSubject,
          "WarpFeatures expects features [K,C,H,W], got " + Shape(features));
  Require(grid.dim() == 4 && grid.size(0) == features.size(0) && grid.size(3) == 2,
          kSubject,
          "WarpFeatures expects a grid [" + std::to_string(features.size(0)) +
              ",H,W,2], got " + Shape(grid));
  // NaN/inf positions (a target pixel with no depth, a point behind the source) must
  // sample nothing rather than poison the features: send them outside [-1,1].
  const torch::Tensor safe_grid =
      torch::nan_to_num(grid.to(features.options()), 2.0, 2.0, -2.0).clamp(-2.0, 2.0);
  // Inside the image the outer half pixel replicates the border pixel (as the `ulr`
  // method's colour samples: zero padding would darken every photo's edge by up to
  // half); outside it, nothing. (The slack absorbs float rounding of an exact edge.)
  const torch::Tensor inside = (safe_grid.abs() <= 1.0 + 1e-6)
                                   .all(3, /*keepdim=*/false)
                                   .unsqueeze(1)
                                   .to(features.dtype());
  return F::grid_sample(features, safe_grid,
                        F::GridSampleFuncOptions()
                            .mode(torch::kBilinear)
                            .padding_mode(torch::kBorder)
                            .align_corners(false)) *
         inside;
}

torch::Tensor IdentityGrid(int64_t count, int64_t height, int64_t width) {
  const auto options = torch::TensorOptions().dtype(torch::kFloat);
  const torch::Tensor xs = (torch::arange(width, options) + 0.5) * (2.0 / width) - 1.0;
  const torch::Tensor ys = (torch::arange(height, options) + 0.5) * (2.0 / height) - 1.0;
  const torch::Tensor gx = xs.view({1, width}).expand({height, width});
  const torch::Tensor gy = ys.view({height, 1}).expand({height, width});
  return torch::stack({gx, gy}, 2)
      .unsqueeze(0)
      .expand({count, height, width, 2})
      .contiguous();
}

torch::Tensor SoftmaxWeights(const torch::Tensor& confidence) {
  Require(confidence.dim() >= 1 && confidence.size(0) > 0, kSubject,
          "SoftmaxWeights expects confidences [K,...], got " + Shape(confidence));
  // NaN counts as "no confidence"; +/-inf and anything beyond +/-1e30 is clamped so that
  // the differences below stay finite. After subtracting the maximum the largest term is
  // exp(0) = 1, so logsumexp is in [0, log K] and no term can overflow, even when all
  // confidences are equal and huge (where exp(c - logsumexp(c)) in float would give 1
  // each).
  // Computed in fp32 whatever the input (1e30 does not exist in fp16).
  constexpr double kBig = 1e30;
  const torch::Tensor c =
      torch::nan_to_num(confidence.to(torch::kFloat), -kBig, kBig, -kBig)
          .clamp(-kBig, kBig);
  const torch::Tensor shifted = c - std::get<0>(c.max(0, /*keepdim=*/true)).detach();
  return torch::exp(shifted - torch::logsumexp(shifted, {0}, /*keepdim=*/true))
      .to(confidence.scalar_type());
}

}  // namespace fvs
