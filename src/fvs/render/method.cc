#include "fvs/render/method.h"

#include <cmath>
#include <map>
#include <mutex>

#include "fvs/net/model_config.h"
#include "fvs/render/fvs_method.h"
#include "fvs/render/ulr.h"
#include "fvs/util/error.h"
#include "fvs/util/hole_filling.h"
#include "fvs/util/progress.h"
#include "fvs/util/string_util.h"

namespace fvs {

bool KnownPrecision(const std::string& name) {
  return name == "fp32" || name == "bf16" || name == "fp16";
}

void RenderOptions::Check() const {
  Require(num_sources >= 0, "--num_sources", "must be at least 1, or 0 (adaptive)");
  Require(max_num_sources >= 1, "--max_num_sources", "must be at least 1");
  Require(selection_tolerance > 0 && std::isfinite(selection_tolerance),
          "--selection_tolerance", "must be positive");
  Require(warp_tolerance > 0 && std::isfinite(warp_tolerance), "--warp_tolerance",
          "must be positive");
  Require(selection_stride >= 1, "selection_stride", "must be at least 1");
  Require(ulr_resolution_weight >= 0 && std::isfinite(ulr_resolution_weight),
          "ulr_resolution_weight", "must be non-negative");
  Require(ulr_num_blend >= 1, "ulr_num_blend", "must be at least 1");
  Require(interpolation == "bilinear" || interpolation == "bicubic", "--interpolation",
          "'" + interpolation + "': must be bilinear or bicubic");
  Require(source_hysteresis >= 0 && std::isfinite(source_hysteresis),
          "--source_hysteresis", "must be finite and non-negative");
  Require(tile_size == -1 || tile_size == 0 || tile_size >= 8, "--tile_size",
          "must be -1 (the network's own), 0 (off) or at least 8");
  Require(tile_overlap >= -1, "--tile_overlap", "must be -1 (the network's own) or >= 0");
  Require(feature_cache_mb >= 0, "--feature_cache_mb", "must be non-negative");
  Require(feature_cache_disk_mb >= 0, "--feature_cache_disk_mb", "must be non-negative");
  Require(device == "auto" || device == "cpu" || device == "cuda", "--device",
          "'" + device + "': must be auto, cpu or cuda");
  Require(KnownPrecision(precision), "--precision",
          "'" + precision + "': must be fp32, bf16 or fp16");
}

Image AtInfinityMask(const Image& depth, const Image& coverage) {
  if (depth.width != coverage.width || depth.height != coverage.height ||
      depth.channels != 1 || coverage.channels != 1) {
    return Image();
  }
  Image mask(depth.width, depth.height, 1);
  for (size_t i = 0; i < mask.data.size(); ++i) {
    const float d = depth.data[i];
    const bool surface = d > 0 && std::isfinite(d);
    mask.data[i] = !surface && coverage.data[i] > 0 ? 1.f : 0.f;
  }
  return mask;
}

namespace {

// Any method, its holes filled afterwards (the same for every method, so comparisons
// between methods stay fair).
class HoleFillingMethod : public Method {
 public:
  explicit HoleFillingMethod(std::unique_ptr<Method> inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  RenderResult Render(const Scene& scene, const TargetView& target) override {
    RenderResult result = inner_->Render(scene, target);
    if (!result.color.empty() && result.coverage.width == result.color.width &&
        result.coverage.height == result.color.height) {
      Timer timer;
      const bool sized = result.depth.width == result.color.width &&
                         result.depth.height == result.color.height;
      FillHoles(result.coverage, sized ? &result.depth : nullptr, &result.color);
      result.timings.blend_s += timer.Seconds();
    }
    return result;
  }

 private:
  std::unique_ptr<Method> inner_;
};

struct Registered {
  MethodFactory factory;
  MethodTraits traits;
};

struct Registry {
  std::mutex mutex;
  std::map<std::string, Registered> methods;
};

// The built-ins are registered here, not by static objects: a static archive would let
// the linker drop an unreferenced registrar.
Registry& GetRegistry() {
  static Registry* registry = [] {
    auto* r = new Registry;
    r->methods["ulr"] = {CreateUlrMethod, {}};
    MethodTraits one_source;
    one_source.single_source = true;
    r->methods["nearest"] = {CreateNearestMethod, one_source};
    // The network under its generic name and under each variant name.
    MethodTraits network;
    network.needs_weights = true;
    for (const std::string& variant : ModelConfig::KnownVariants()) {
      r->methods[variant] = {[variant](const RenderOptions& options) {
                               return CreateFvsMethod(variant, options);
                             },
                             network};
    }
    return r;
  }();
  return *registry;
}

}  // namespace

void RegisterMethod(const std::string& name, MethodFactory factory, MethodTraits traits) {
  Registry& registry = GetRegistry();
  std::lock_guard<std::mutex> lock(registry.mutex);
  registry.methods[name] = {std::move(factory), traits};
}

MethodTraits TraitsOfMethod(const std::string& name) {
  Registry& registry = GetRegistry();
  std::lock_guard<std::mutex> lock(registry.mutex);
  const auto it = registry.methods.find(name);
  if (it != registry.methods.end()) return it->second.traits;
  MethodTraits network;
  network.needs_weights = true;
  return network;
}

std::vector<std::string> RegisteredMethods() {
  Registry& registry = GetRegistry();
  std::lock_guard<std::mutex> lock(registry.mutex);
  std::vector<std::string> names;
  for (const auto& [name, method] : registry.methods) names.push_back(name);
  return names;
}

std::string WorkspaceFeatureCacheDir(const std::string& workspace_path) {
  return JoinPaths(workspace_path, "fvs/features");
}

std::unique_ptr<Method> CreateMethod(const std::string& name,
                                     const RenderOptions& options) {
  MethodFactory factory;
  {
    Registry& registry = GetRegistry();
    std::lock_guard<std::mutex> lock(registry.mutex);
    const auto it = registry.methods.find(name);
    if (it != registry.methods.end()) factory = it->second.factory;
  }
  if (!factory) {
    if (name == "fvs") {
      if (options.model_path.empty()) {
        throw Error("--method fvs",
                    "method fvs needs model weights: --model_path <weights.safetensors>");
      }
      throw Error(
          "--method fvs",
          "the network is not available in this build (use --method ulr or nearest)");
    }
    std::string known;
    for (const std::string& n : RegisteredMethods())
      known += (known.empty() ? "" : ", ") + n;
    throw Error("--method " + name, "unknown method (known: " + known + ", fvs)");
  }
  std::unique_ptr<Method> method = factory(options);
  if (!options.fill_holes) return method;
  return std::make_unique<HoleFillingMethod>(std::move(method));
}

}  // namespace fvs
