// The Free View Synthesis network (Riegler & Koltun 2020) in LibTorch:
//   Encode  source images [K,3,H,W] in [-1,1] -> features [K,C,H,W]   (VGG16 stages 1-3 +
//   U-Net
//           decoder, average pooling)
//   WarpFeatures  bilinear sampling of the features at the target pixels' source
//   positions Blend   recurrent U-Net over the sources (7 ConvGRUs for the reference
//   layout), per-source
//           RGB + confidence, softmax over sources through log-sum-exp.
// Variants are selected by ModelConfig (model_config.h). Only torch code includes this
// header.
#pragma once

#include <torch/torch.h>

#include <string>
#include <vector>

#include "fvs/net/model_config.h"

namespace fvs {

struct SafeTensorsFile;
class AggregateBlenderImpl;

// LibTorch uses one thread here unless told; use fvs::DefaultNumThreads()
// (FVS_NUM_THREADS).
void ConfigureTorchThreads();

// A 2D convolution without activation: dense kxk, or depthwise kxk + pointwise 1x1 when
// `separable`. Remembers its layout so that FLOPs can be counted without running it.
class ConvUnitImpl : public torch::nn::Module {
 public:
  // `level`: log2 of the down-sampling at which it runs (for FLOP counts).
  ConvUnitImpl(int in_channels, int out_channels, int kernel, bool separable, int level);
  torch::Tensor forward(const torch::Tensor& x);
  int64_t MacsPerPixel() const;
  int level() const { return level_; }

 private:
  int in_, out_, kernel_, level_;
  bool separable_;
  torch::nn::Conv2d conv_{nullptr}, depthwise_{nullptr}, pointwise_{nullptr};
};
TORCH_MODULE(ConvUnit);

// Convolutional GRU: z, r = sigmoid(conv([x, h])); c = relu(conv([x, r*h]));
// h' = (1 - z) h + z c. An undefined h means h0 = 0.
class ConvGruImpl : public torch::nn::Module {
 public:
  ConvGruImpl(int in_channels, int hidden_channels, bool separable, int level);
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& h);
  std::vector<const ConvUnitImpl*> Units() const;

 private:
  int hidden_;
  ConvUnit gates_{nullptr}, candidate_{nullptr};
};
TORCH_MODULE(ConvGru);

struct BlendOutput {
  torch::Tensor rgb;             // [1,3,H,W]; clamped to [-1,1] when not training
  torch::Tensor weights;         // [K,1,H,W] softmax weights (empty without soft-argmax)
  torch::Tensor per_source_rgb;  // [K,3,H,W] (empty without soft-argmax)
};

class FvsNetImpl : public torch::nn::Module {
 public:
  explicit FvsNetImpl(const ModelConfig& config);
  const ModelConfig& config() const { return config_; }

  // [K,3,H,W] in [-1,1], any H, W -> [K,config.EncodedChannels(),H,W] (the features,
  // then the image itself with rgb_skip).
  torch::Tensor Encode(const torch::Tensor& images);
  // warped [K,C,Ht,Wt], valid_depth [1,1,Ht,Wt], valid_warp [K,1,Ht,Wt] (float 0/1),
  // ulr_log_weights [K,1,Ht,Wt] (UlrLogWeights; needed when config.ulr_prior > 0).
  BlendOutput Blend(const torch::Tensor& warped, const torch::Tensor& valid_depth,
                    const torch::Tensor& valid_warp,
                    const torch::Tensor& ulr_log_weights = {});
  // Training: Encode + WarpFeatures + Blend. grid [K,Ht,Wt,2] as in WarpFeatures.
  BlendOutput Forward(const torch::Tensor& images, const torch::Tensor& grid,
                      const torch::Tensor& valid_depth, const torch::Tensor& valid_warp,
                      const torch::Tensor& ulr_log_weights = {});

  int64_t EncoderParameterCount() const;
  int64_t BlenderParameterCount() const;
  // Analytic FLOPs (2 x multiply-adds of every conv at the padded size) per source.
  double EncodeFlops(int height, int width) const;
  double BlendFlops(int height, int width) const;

 private:
  // One pass of the blending U-Net over a batch; `state` (one tensor per GRU, undefined =
  // zero) is read and replaced when the net is recurrent.
  torch::Tensor BlendPass(const torch::Tensor& x, std::vector<torch::Tensor>* state);

  ModelConfig config_;
  // Encoder: convs of every down stage, then of every up stage (deepest first).
  std::vector<std::vector<ConvUnit>> encoder_down_, encoder_up_;
  // Blender stages in order: down 0..L-1, then up L-2..0. Each stage: plain convs, then
  // either a GRU or one more plain conv as its last layer.
  struct Stage {
    std::vector<ConvUnit> convs;
    ConvGru gru{nullptr};
  };
  std::vector<Stage> blend_stages_;
  torch::nn::Conv2d rgb_head_{nullptr}, confidence_head_{nullptr};
  // The whole blender of ModelConfig::blender == "aggregate" (net/aggregate.h).
  std::shared_ptr<AggregateBlenderImpl> aggregate_;
  std::vector<const ConvUnitImpl*> encoder_units_, blend_units_;
};
TORCH_MODULE(FvsNet);

// Bilinear sampling (grid_sample, align_corners = false): grid [K,Ht,Wt,2] holds source
// positions in [-1,1] (x then y; -1 = left edge of the first pixel). Within the image the
// outer half pixel replicates the border pixel; positions outside [-1,1] and non-finite
// ones sample nothing (zeros).
torch::Tensor WarpFeatures(const torch::Tensor& features, const torch::Tensor& grid);

// The grid that maps every target pixel onto itself ([K,H,W,2]).
torch::Tensor IdentityGrid(int64_t count, int64_t height, int64_t width);

// Softmax over dim 0 of confidences [K,1,H,W] computed as exp(c - max - logsumexp(c -
// max)): sums to 1 and stays finite for equal, huge (+/-1e30), infinite or NaN
// confidences.
torch::Tensor SoftmaxWeights(const torch::Tensor& confidence);

// Weights as safetensors: every parameter and buffer by its module path, fp32 or fp16,
// the config JSON in __metadata__["fvs_config"]. Atomic.
void SaveWeights(const FvsNet& net, const ModelConfig& config, const std::string& path,
                 bool fp16);
// Builds the network the file's config names and loads it; *config receives the config.
FvsNet LoadModel(const std::string& path, ModelConfig* config);
// Copies every tensor into `net`; throws one fvs::Error(subject, ...) listing every
// missing, unexpected, mis-shaped, wrongly typed (F32, F16, BF16 accepted) or non-finite
// tensor.
void LoadWeightsInto(FvsNet& net, const SafeTensorsFile& file,
                     const std::string& subject);

// What view_synthesis_model_info prints for one network.
struct ModelInfo {
  ModelConfig config;
  int width = 0, height = 0;
  int64_t encoder_parameters = 0, blender_parameters = 0;
  double encode_flops = 0, blend_flops = 0;        // per source
  double encode_seconds = -1, blend_seconds = -1;  // one K=1 forward; -1 = not timed
};
ModelInfo DescribeModel(FvsNet& net, int width, int height, bool time_forward);
std::string FormatModelInfo(const ModelInfo& info);

}  // namespace fvs
