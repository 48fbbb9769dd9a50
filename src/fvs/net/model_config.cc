#include "fvs/net/model_config.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "fvs/util/error.h"

namespace fvs {
namespace {

const char kSubject[] = "model config";

std::string JoinNames(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s;
}

template <typename T>
void Read(const nlohmann::json& json, const char* key, T* value) {
  if (!json.contains(key)) return;
  try {
    *value = json.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw Error(kSubject, std::string("field \"") + key +
                              "\" has the wrong type: " + json.at(key).dump());
  }
}

}  // namespace

std::vector<std::string> ModelConfig::KnownVariants() {
  return {"fvs", "fvs_nogru", "fvs_nomasks", "fvs_noinfdepth", "fvs_single", "fvs_fast",
          "fvs_agg"};
}

ModelConfig ModelConfig::ForVariant(const std::string& name) {
  ModelConfig c;
  c.variant = name;
  if (name == "fvs") {
  } else if (name == "fvs_nogru") {
    c.use_gru = false;
  } else if (name == "fvs_nomasks") {
    c.use_masks = false;
  } else if (name == "fvs_noinfdepth") {
    c.inf_depth = false;
  } else if (name == "fvs_single") {
    c.soft_argmax = false;
  } else if (name == "fvs_fast") {
    // For CPUs, about 20x fewer FLOPs than fvs per source: 32 feature channels, one conv
    // less in the encoder's first two stages, a blending U-Net of widths 16/24/32/48 with
    // two convs per stage (conv + ConvGRU). Still recurrent at every level, with
    // per-source confidences. The blend widths grow slowly with depth because a stage
    // costs width^2 / 4^level: doubling per level (16/32/64/128) made every level cost
    // the same, 4x the full-resolution one in all, for 33 GFLOPs per source at 480x270;
    // these widths cost 18. Dense convs on purpose: LibTorch 1.13's CPU depthwise convs
    // are slow, slower per FLOP by far than dense ones (doc/network.md has the timings);
    // depthwise_separable stays available for GPUs.
    c.feature_channels = 32;
    c.encoder_channels = {32, 64, 128};
    c.encoder_convs = {1, 1, 2};
    c.blend_channels = {16, 24, 32, 48};
    c.blend_convs_per_stage = 2;
    c.depthwise_separable = false;
    // Trains on a CPU in hours rather than weeks: it starts as the ULR blend of the
    // sources that see a pixel and learns confidences and corrections from there.
    c.rgb_skip = true;
    c.ulr_prior = 1.0;
  } else if (name == "fvs_agg") {
    // Trains at tens of samples a second on a 2-core CPU: no encoder (the paper's
    // ablation without one loses little), statistics across the warped sources instead
    // of a recurrence, starts as the ULR blend (net/aggregate.h).
    c.blender = "aggregate";
    c.feature_channels = 0;
    c.encoder_channels = {};
    c.encoder_convs = {};
    c.blend_channels = {16, 24};
    c.blend_convs_per_stage = 1;
    c.use_gru = false;
    c.rgb_skip = true;
    c.ulr_prior = 1.0;
  } else {
    throw Error(kSubject, "unknown network variant '" + name +
                              "' (known: " + JoinNames(KnownVariants()) + ")");
  }
  return c;
}

std::string ModelConfig::ToJson() const {
  nlohmann::ordered_json j;
  j["variant"] = variant;
  j["blender"] = blender;
  j["feature_channels"] = feature_channels;
  j["use_masks"] = use_masks;
  j["use_gru"] = use_gru;
  j["soft_argmax"] = soft_argmax;
  j["inf_depth"] = inf_depth;
  j["encoder_channels"] = encoder_channels;
  j["encoder_convs"] = encoder_convs;
  j["blend_channels"] = blend_channels;
  j["blend_convs_per_stage"] = blend_convs_per_stage;
  j["depthwise_separable"] = depthwise_separable;
  j["rgb_skip"] = rgb_skip;
  j["mask_prior"] = mask_prior;
  j["ulr_prior"] = ulr_prior;
  j["ulr_num_blend"] = ulr_num_blend;
  j["ulr_resolution_weight"] = ulr_resolution_weight;
  return j.dump();
}

ModelConfig ModelConfig::FromJson(const std::string& text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw Error(kSubject, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw Error(kSubject, "not a JSON object");
  if (!j.contains("variant") || !j["variant"].is_string()) {
    throw Error(kSubject, "no \"variant\" string");
  }
  // A misspelt field would silently build the default network: refuse it.
  static const char* const kFields[] = {"variant",
                                        "blender",
                                        "feature_channels",
                                        "use_masks",
                                        "use_gru",
                                        "soft_argmax",
                                        "inf_depth",
                                        "encoder_channels",
                                        "encoder_convs",
                                        "blend_channels",
                                        "blend_convs_per_stage",
                                        "depthwise_separable",
                                        "rgb_skip",
                                        "mask_prior",
                                        "ulr_prior",
                                        "ulr_num_blend",
                                        "ulr_resolution_weight"};
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool known = false;
    for (const char* field : kFields) known = known || it.key() == field;
    if (!known) throw Error(kSubject, "unknown field \"" + it.key() + "\"");
  }
  ModelConfig c = ForVariant(j["variant"].get<std::string>());
  Read(j, "blender", &c.blender);
  Read(j, "feature_channels", &c.feature_channels);
  Read(j, "use_masks", &c.use_masks);
  Read(j, "use_gru", &c.use_gru);
  Read(j, "soft_argmax", &c.soft_argmax);
  Read(j, "inf_depth", &c.inf_depth);
  Read(j, "encoder_channels", &c.encoder_channels);
  Read(j, "encoder_convs", &c.encoder_convs);
  Read(j, "blend_channels", &c.blend_channels);
  Read(j, "blend_convs_per_stage", &c.blend_convs_per_stage);
  Read(j, "depthwise_separable", &c.depthwise_separable);
  Read(j, "rgb_skip", &c.rgb_skip);
  Read(j, "mask_prior", &c.mask_prior);
  Read(j, "ulr_prior", &c.ulr_prior);
  Read(j, "ulr_num_blend", &c.ulr_num_blend);
  Read(j, "ulr_resolution_weight", &c.ulr_resolution_weight);
  c.Check();
  return c;
}

void ModelConfig::Check() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error(kSubject, what);
  };
  constexpr int kMaxChannels = 4096;
  require(blender == "unet" || blender == "aggregate",
          "blender must be unet or aggregate, not '" + blender + "'");
  if (blender == "aggregate") {
    require(encoder_channels.empty() && encoder_convs.empty() && feature_channels == 0,
            "the aggregate blender has no encoder (encoder_channels [], "
            "feature_channels 0)");
    require(rgb_skip && use_masks && soft_argmax && !use_gru && ulr_prior > 0,
            "the aggregate blender needs rgb_skip, use_masks, soft_argmax, ulr_prior > 0 "
            "and no GRU");
    require(blend_channels.size() == 2 && blend_channels[0] >= 1 &&
                blend_channels[1] >= 1 && blend_channels[0] <= kMaxChannels &&
                blend_channels[1] <= kMaxChannels,
            "the aggregate blender needs two blend_channels in [1, 4096]");
  } else {
    CheckUnet();
  }
  require(std::isfinite(mask_prior) && mask_prior >= 0 && mask_prior <= 30,
          "mask_prior must be in [0, 30]");
  require(mask_prior == 0 || (use_masks && soft_argmax),
          "mask_prior needs use_masks and soft_argmax");
  require(std::isfinite(ulr_prior) && ulr_prior >= 0 && ulr_prior <= 10,
          "ulr_prior must be in [0, 10]");
  require(ulr_prior == 0 || (use_masks && soft_argmax),
          "ulr_prior needs use_masks and soft_argmax");
  require(ulr_num_blend >= 1 && ulr_num_blend <= 64, "ulr_num_blend must be in [1, 64]");
  require(std::isfinite(ulr_resolution_weight) && ulr_resolution_weight >= 0 &&
              ulr_resolution_weight <= 100,
          "ulr_resolution_weight must be in [0, 100]");
}

void ModelConfig::CheckUnet() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error(kSubject, what);
  };
  constexpr int kMaxChannels = 4096;
  require(feature_channels >= 1 && feature_channels <= kMaxChannels,
          "feature_channels must be in [1, 4096]");
  require(encoder_channels.size() >= 2 && encoder_channels.size() <= 6,
          "encoder_channels needs 2 to 6 stages");
  require(encoder_convs.size() == encoder_channels.size(),
          "encoder_convs needs one count per encoder stage");
  for (size_t i = 0; i < encoder_channels.size(); ++i) {
    require(encoder_channels[i] >= 1 && encoder_channels[i] <= kMaxChannels,
            "encoder_channels must be in [1, 4096]");
    require(encoder_convs[i] >= 1 && encoder_convs[i] <= 8,
            "encoder_convs must be in [1, 8]");
  }
  require(blend_channels.size() >= 2 && blend_channels.size() <= 6,
          "blend_channels needs 2 to 6 levels");
  for (int c : blend_channels) {
    require(c >= 1 && c <= kMaxChannels, "blend_channels must be in [1, 4096]");
  }
  require(blend_convs_per_stage >= 1 && blend_convs_per_stage <= 8,
          "blend_convs_per_stage must be in [1, 8]");
  require(!rgb_skip || soft_argmax, "rgb_skip needs soft_argmax (per-source colours)");
}

}  // namespace fvs
