// What network a set of weights belongs to: the variant name and the few numbers that fix
// its layout. Stored as JSON in the weights' __metadata__ ("fvs_config") so that a file
// always says what it is. No torch here: the renderer and the commands read configs
// without LibTorch.
#pragma once

#include <string>
#include <vector>

namespace fvs {

struct ModelConfig {
  // One of KnownVariants() (the table in model_config.cc).
  std::string variant = "fvs";
  // "unet": the paper's recurrent blending U-Net over encoded features. "aggregate":
  // no encoder, per-pixel statistics across the warped photos and narrow convs
  // (net/aggregate.h); needs encoder_channels empty, feature_channels 0, rgb_skip,
  // use_masks, soft_argmax, ulr_prior > 0, no GRU and two blend_channels (w0, w1).
  std::string blender = "unet";
  // Encoder output = warped feature channels per source.
  int feature_channels = 64;
  // Valid-depth and valid-warp masks appended to the warped features (66 channels in).
  bool use_masks = true;
  // Last conv of every blending stage is a ConvGRU whose state carries across sources.
  bool use_gru = true;
  // Per-source RGB + confidence, softmax over sources. false: one RGB head on the final
  // state.
  bool soft_argmax = true;
  // Pixels without target depth are warped at infinity (geometry/warp.h); false: they
  // have no valid warp.
  bool inf_depth = true;
  // Encoder: VGG16 stage widths and conv counts (stages 1-3); decoder mirrors the widths.
  // Empty: no encoder (the photos' colours are warped as they are).
  std::vector<int> encoder_channels = {64, 128, 256};
  std::vector<int> encoder_convs = {2, 2, 3};
  // Blending U-Net: widths of the encoder levels (the decoder mirrors all but the
  // deepest).
  std::vector<int> blend_channels = {64, 128, 256, 512};
  // 3x3 convs per blending stage, the last of which is the ConvGRU when use_gru.
  int blend_convs_per_stage = 3;
  // Depthwise 3x3 + pointwise 1x1 instead of dense 3x3 convs (the CPU variant).
  bool depthwise_separable = false;
  // The encoder's output also carries the source's own RGB (3 more channels, warped with
  // the features), and each source's RGB head predicts a correction to its warped
  // colour (head initialised to zero). Not in the paper: a network that starts as an
  // average of the warped sources trains in far fewer steps (the CPU variant).
  bool rgb_skip = false;
  // > 0: mask_prior * (valid_warp - 1) is added to each source's confidence, so a source
  // that does not see a pixel starts with e^-mask_prior of the weight (needs use_masks
  // and soft_argmax). 0 = the paper's purely learnt confidences.
  double mask_prior = 0;
  // > 0: ulr_prior * log(ULR weight) (net/ulr_weights.h, floored at kUlrWeightFloor) is
  // added to each source's confidence. With rgb_skip and the zero-initialised heads the
  // untrained net renders exactly what the `ulr` method renders, and training learns
  // corrections to it (not in the paper; the CPU variant). The ULR settings are part of
  // the model so that a set of weights always blends from the prior it was trained with.
  double ulr_prior = 0;
  int ulr_num_blend = 4;
  double ulr_resolution_weight = 0.2;

  // Throws fvs::Error for an unknown name, listing the known ones.
  static ModelConfig ForVariant(const std::string& name);
  static std::vector<std::string> KnownVariants();

  std::string ToJson() const;
  // Starts from ForVariant(json["variant"]) and overrides the fields present; throws
  // fvs::Error("model config", ...) on bad JSON, wrong types or impossible values.
  static ModelConfig FromJson(const std::string& json);

  // Throws fvs::Error("model config", ...) when the numbers cannot make a network.
  void Check() const;
  // The part of Check() for the "unet" blender (encoder and U-Net layout).
  void CheckUnet() const;

  // Channels of Encode's output (and of the warped features) per source.
  int EncodedChannels() const { return feature_channels + (rgb_skip ? 3 : 0); }
  // Input channels of the blending net per source.
  int BlendInputChannels() const { return EncodedChannels() + (use_masks ? 2 : 0); }
  // Input sizes are padded to a multiple of these (total down-sampling of the U-Nets).
  int EncoderStride() const {
    return encoder_channels.empty() ? 1 : 1 << (encoder_channels.size() - 1);
  }
  int BlendStride() const { return 1 << (blend_channels.size() - 1); }

  // Calls visit(json_name, field) for every field above, in the order of the JSON.
  // ToJson, FromJson and its refusal of unknown names are built on it, so a new field is
  // its declaration above plus one line here. (Self: ModelConfig or const ModelConfig.)
  template <typename Self, typename Visit>
  static void ForEachField(Self& c, Visit&& visit) {
    visit("variant", c.variant);
    visit("blender", c.blender);
    visit("feature_channels", c.feature_channels);
    visit("use_masks", c.use_masks);
    visit("use_gru", c.use_gru);
    visit("soft_argmax", c.soft_argmax);
    visit("inf_depth", c.inf_depth);
    visit("encoder_channels", c.encoder_channels);
    visit("encoder_convs", c.encoder_convs);
    visit("blend_channels", c.blend_channels);
    visit("blend_convs_per_stage", c.blend_convs_per_stage);
    visit("depthwise_separable", c.depthwise_separable);
    visit("rgb_skip", c.rgb_skip);
    visit("mask_prior", c.mask_prior);
    visit("ulr_prior", c.ulr_prior);
    visit("ulr_num_blend", c.ulr_num_blend);
    visit("ulr_resolution_weight", c.ulr_resolution_weight);
  }
};

}  // namespace fvs
