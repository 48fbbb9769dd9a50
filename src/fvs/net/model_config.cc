#include "fvs/net/model_config.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "fvs/util/error.h"
#include "fvs/util/json_number.h"

namespace fvs {
namespace {

const char kSubject[] = "model config";
// A field of weights files written before the variant that used it was removed.
const char kRemovedRelativeInputs[] = "relative_inputs";

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

// Whole numbers through JsonToInt: get<int>() of 1e30 is undefined behaviour (found by
// safetensors_fuzzer in a weights file's fvs_config).
void ReadWhole(const nlohmann::json& v, const char* key, int* out) {
  if (!JsonToInt(v, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
                 out)) {
    throw Error(kSubject,
                std::string("field \"") + key + "\" is not a whole number: " + v.dump());
  }
}

void Read(const nlohmann::json& json, const char* key, int* value) {
  if (json.contains(key)) ReadWhole(json.at(key), key, value);
}

void Read(const nlohmann::json& json, const char* key, std::vector<int>* value) {
  if (!json.contains(key)) return;
  const nlohmann::json& list = json.at(key);
  if (!list.is_array()) {
    throw Error(kSubject,
                std::string("field \"") + key + "\" is not a list: " + list.dump());
  }
  value->assign(list.size(), 0);
  for (size_t i = 0; i < list.size(); ++i) ReadWhole(list[i], key, &(*value)[i]);
}

// The layout of fvs_agg (net/aggregate.h).
void MakeAggregate(ModelConfig* c) {
  c->blender = "aggregate";
  c->feature_channels = 0;
  c->encoder_channels = {};
  c->encoder_convs = {};
  c->blend_channels = {16, 24};
  c->blend_convs_per_stage = 1;
  c->use_gru = false;
  c->rgb_skip = true;
  c->ulr_prior = 1.0;
}

// Every variant once: its name and how it differs from the default (the paper's `fvs`).
struct Variant {
  const char* name;
  void (*apply)(ModelConfig* c);
};

const Variant kVariants[] = {
    {"fvs", [](ModelConfig*) {}},
    {"fvs_nogru", [](ModelConfig* c) { c->use_gru = false; }},
    {"fvs_nomasks", [](ModelConfig* c) { c->use_masks = false; }},
    {"fvs_noinfdepth", [](ModelConfig* c) { c->inf_depth = false; }},
    {"fvs_single", [](ModelConfig* c) { c->soft_argmax = false; }},
    // For CPUs, about 20x fewer FLOPs than fvs per source: 32 feature channels, one conv
    // less in the encoder's first two stages, a blending U-Net of widths 16/24/32/48 with
    // two convs per stage (conv + ConvGRU). Still recurrent at every level, with
    // per-source confidences. The blend widths grow slowly with depth because a stage
    // costs width^2 / 4^level (doc/network.md has the FLOPs and timings). Dense convs on
    // purpose: LibTorch 1.13's CPU depthwise convs are slower per FLOP by far;
    // depthwise_separable stays available for GPUs. It starts as the ULR blend of the
    // sources that see a pixel and learns confidences and corrections from there.
    {"fvs_fast",
     [](ModelConfig* c) {
       c->feature_channels = 32;
       c->encoder_channels = {32, 64, 128};
       c->encoder_convs = {1, 1, 2};
       c->blend_channels = {16, 24, 32, 48};
       c->blend_convs_per_stage = 2;
       c->depthwise_separable = false;
       c->rgb_skip = true;
       c->ulr_prior = 1.0;
     }},
    // Trains at samples a second on a 2-core CPU: no encoder (the paper's ablation
    // without one loses little), statistics across the warped sources instead of a
    // recurrence, starts as the ULR blend (net/aggregate.h).
    {"fvs_agg", [](ModelConfig* c) { MakeAggregate(c); }},
};

}  // namespace

std::vector<std::string> ModelConfig::KnownVariants() {
  std::vector<std::string> names;
  for (const Variant& v : kVariants) names.push_back(v.name);
  return names;
}

ModelConfig ModelConfig::ForVariant(const std::string& name) {
  for (const Variant& v : kVariants) {
    if (name != v.name) continue;
    ModelConfig c;
    c.variant = name;
    v.apply(&c);
    return c;
  }
  throw Error(kSubject, "unknown network variant '" + name +
                            "' (known: " + JoinNames(KnownVariants()) + ")");
}

std::string ModelConfig::ToJson() const {
  nlohmann::ordered_json j;
  ForEachField(*this, [&](const char* name, const auto& value) { j[name] = value; });
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
  std::vector<std::string> fields;
  const ModelConfig defaults;
  ForEachField(defaults, [&](const char* name, const auto&) { fields.push_back(name); });
  // Files written while the experimental fvs_agg_rel existed carry its switch, false in
  // every fvs_agg file; that one is the network it names today.
  if (j.contains(kRemovedRelativeInputs)) {
    if (j[kRemovedRelativeInputs] != false) {
      throw Error(kSubject,
                  "\"relative_inputs\" belongs to the removed experimental variant "
                  "fvs_agg_rel (doc/training.md); these weights need colmap-fvs of "
                  "commit d1b9f5e or earlier");
    }
    j.erase(kRemovedRelativeInputs);
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (std::find(fields.begin(), fields.end(), it.key()) == fields.end()) {
      throw Error(kSubject, "unknown field \"" + it.key() + "\"");
    }
  }
  ModelConfig c = ForVariant(j["variant"].get<std::string>());
  ForEachField(c, [&](const char* name, auto& value) { Read(j, name, &value); });
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
