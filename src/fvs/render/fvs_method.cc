#include "fvs/render/fvs_method.h"

#include <torch/torch.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <list>
#include <map>
#include <vector>

#include "fvs/net/image_tensor.h"
#include "fvs/net/net.h"
#include "fvs/net/precision.h"
#include "fvs/render/feature_store.h"
#include "fvs/render/prepare.h"
#include "fvs/render/ulr.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

// The prior of ModelConfig::ulr_prior: ULR log-weights [K,1,H,W] of the prepared
// sources, from the same surface points the `ulr` method blends at (`depth`: the
// target's, as rendered for it).
torch::Tensor UlrLogWeightTensor(const Scene& scene, const TargetView& target,
                                 const PreparedTarget& prepared, const Image& depth,
                                 const torch::Tensor& warp_mask,
                                 const ModelConfig& config, int num_threads) {
  const PinholeCamera& cam = target.camera;
  const int w = cam.width, h = cam.height;
  const int64_t num_pixels = static_cast<int64_t>(w) * h;
  const UlrSources sources = MakeUlrSources(scene, target, prepared);
  const double far_distance = UlrFarDistance(sources);
  std::vector<double> points(3 * num_pixels);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3d p = UlrSurfacePoint(cam, depth, x, y, far_distance);
      const int64_t i = static_cast<int64_t>(y) * w + x;
      for (int c = 0; c < 3; ++c) points[3 * i + c] = p[c];
    }
  }
  const int64_t k = warp_mask.size(0);
  const torch::Tensor sees = warp_mask.reshape({k, num_pixels}).contiguous();
  torch::Tensor log_weights = torch::empty({k, num_pixels}, torch::kFloat32);
  UlrOptions settings;
  settings.num_blend = config.ulr_num_blend;
  settings.resolution_weight = config.ulr_resolution_weight;
  UlrLogWeights(points.data(), num_pixels, sources, sees.data_ptr<float>(), settings,
                log_weights.data_ptr<float>(), num_threads);
  return log_weights.reshape({k, 1, h, w});
}

// A block of the target, [y0, y1) x [x0, x1), and the larger box around it that the
// network sees when blending it.
struct Tile {
  int y0, y1, x0, x1;
  int cy0, cy1, cx0, cx1;
};

// Rows [y0, y1) and columns [x0, x1) of t, whose rows are dimension `dim` and columns the
// next one (2 for [N,C,H,W], 1 for a [N,H,W,2] sampling grid). A view, not a copy.
torch::Tensor Box(const torch::Tensor& t, int y0, int y1, int x0, int x1,
                  int64_t dim = 2) {
  return t.narrow(dim, y0, y1 - y0).narrow(dim + 1, x0, x1 - x0);
}

std::vector<Tile> Tiles(int width, int height, int tile_size, int overlap) {
  if (tile_size <= 0 || (width <= tile_size && height <= tile_size)) {
    return {Tile{0, height, 0, width, 0, height, 0, width}};
  }
  // Equal tiles rather than full ones and a sliver, split at even pixels: with an even
  // overlap every context box then starts where the whole target's 2x down-sampling
  // pairs pixels, so a tile computes what the whole target would (fvs_agg's
  // half-resolution branches; tested).
  const int rows = (height + tile_size - 1) / tile_size;
  const int cols = (width + tile_size - 1) / tile_size;
  auto split = [](int size, int i, int n) {
    return i == n ? size : size * i / n / 2 * 2;
  };
  std::vector<Tile> tiles;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      Tile t;
      t.y0 = split(height, r, rows);
      t.y1 = split(height, r + 1, rows);
      t.x0 = split(width, c, cols);
      t.x1 = split(width, c + 1, cols);
      if (t.y1 <= t.y0 || t.x1 <= t.x0) continue;
      t.cy0 = std::max(0, t.y0 - overlap);
      t.cy1 = std::min(height, t.y1 + overlap);
      t.cx0 = std::max(0, t.x0 - overlap);
      t.cx1 = std::min(width, t.x1 + overlap);
      tiles.push_back(t);
    }
  }
  return tiles;
}

class FvsMethod : public Method {
 public:
  FvsMethod(FvsNet net, ModelConfig config, const RenderOptions& options,
            torch::Device device, torch::ScalarType dtype)
      : net_(std::move(net)),
        config_(std::move(config)),
        options_(options),
        device_(device),
        dtype_(dtype) {
    net_->eval();
    net_->to(device_, dtype_);
    // Tiles by default: fvs_agg's narrow full-resolution layers are bound by memory
    // traffic, and tiles of 160 pixels that stay in cache render far faster than one 512
    // tile (benchmark/README_render.md); its receptive field
    // reaches less than 24 pixels (the tiled-equals-whole test). The encoder-decoder
    // variants keep 512 and 32.
    const bool aggregate = config_.blender == "aggregate";
    if (options_.tile_size < 0) options_.tile_size = aggregate ? 160 : 512;
    if (options_.tile_overlap < 0) options_.tile_overlap = aggregate ? 24 : 32;
    // Channels-last: oneDNN's convolutions run faster on it on a CPU
    // (benchmark/README_render.md), and it is the layout CUDA's tensor cores want.
    for (auto& p : net_->parameters()) {
      if (p.dim() == 4) p.set_data(p.contiguous(torch::MemoryFormat::ChannelsLast));
    }
    // A network without an encoder (fvs_agg) warps the photos themselves: nothing to
    // keep.
    if (!options_.feature_cache_dir.empty() && !config_.encoder_channels.empty()) {
      try {  // an optimisation: a read-only workspace renders, only slower
        store_ = std::make_unique<FeatureStore>(
            options_.feature_cache_dir, options_.model_path, config_.variant,
            options_.precision, int64_t{options_.feature_cache_disk_mb} << 20);
      } catch (const std::exception& e) {
        std::cerr << "WARNING: " << e.what() << "; features are not kept on disk\n";
      }
    }
  }

  std::string name() const override { return config_.variant; }

  RenderResult Render(const Scene& scene, const TargetView& target) override {
    c10::InferenceMode inference;
    PreparedTarget prepared = PrepareTarget(scene, target, options_);
    RenderResult result;
    result.depth = std::move(prepared.depth);
    result.sources = prepared.sources;
    result.timings = prepared.timings;
    const int w = target.camera.width, h = target.camera.height;
    result.color = Image(w, h, 3, 0.0f);
    result.confidence = Image(w, h, 1, 0.0f);
    result.coverage = Image(w, h, 1, 0.0f);
    result.infinity = Image(w, h, 1, 0.0f);
    const int k = static_cast<int>(prepared.sources.size());
    if (k == 0) return result;  // no source sees anything: black, coverage 0

    Timer timer;
    // Held by value (a reference-counted handle): the cache may drop a source while this
    // frame still uses it.
    std::vector<torch::Tensor> features(k);
    std::vector<torch::Tensor> grids(k), valid_warp(k);
    for (int i = 0; i < k; ++i) {
      const int view = prepared.sources[i].view_index;
      features[i] = Features(scene, view);
      const Image grid =
          GridSampleCoordinates(prepared.warps[i], scene.view(view).camera.width,
                                scene.view(view).camera.height);
      grids[i] = ImageToTensor(grid).permute({0, 2, 3, 1}).to(device_);  // [1,H,W,2]
      valid_warp[i] = ImageToTensor(prepared.warps[i].valid_warp).to(device_);
    }
    result.timings.encode_s = encode_seconds_;
    encode_seconds_ = 0;
    torch::Tensor valid_depth = ImageToTensor(prepared.warps[0].valid_depth).to(device_);
    torch::Tensor warp_mask = torch::cat(valid_warp, 0);
    if (!config_.inf_depth) {
      // Without the "far away" convention a pixel with no surface has no valid warp.
      warp_mask = warp_mask * valid_depth;
    }
    torch::Tensor ulr_log_weights;
    if (config_.ulr_prior > 0) {
      ulr_log_weights = UlrLogWeightTensor(scene, target, prepared, result.depth,
                                           warp_mask.cpu(), config_, options_.num_threads)
                            .to(device_);
    }
    // Sampling positions need fp32 (bf16 would move them by pixels): warp in fp32.
    for (torch::Tensor& f : features) f = f.to(torch::kFloat32);
    // [-1,1] RGB and the share of the blend from sources that see the pixel.
    const auto fp32 = torch::TensorOptions().dtype(torch::kFloat32).device(device_);
    torch::Tensor rgb = torch::zeros({1, 3, h, w}, fp32);
    torch::Tensor seen_weight = torch::zeros({1, 1, h, w}, fp32);
    bool have_weights = false;
    for (const Tile& tile : Tiles(w, h, options_.tile_size, options_.tile_overlap)) {
      // Pixels [y0, y1) x [x0, x1) of the target, computed over the larger context box.
      auto context = [&](const torch::Tensor& t, int64_t dim = 2) {
        return Box(t, tile.cy0, tile.cy1, tile.cx0, tile.cx1, dim);
      };
      auto core = [&](const torch::Tensor& t) {  // of a context-sized tensor
        return Box(t, tile.y0 - tile.cy0, tile.y1 - tile.cy0, tile.x0 - tile.cx0,
                   tile.x1 - tile.cx0);
      };
      auto target_core = [&](const torch::Tensor& t) {
        return Box(t, tile.y0, tile.y1, tile.x0, tile.x1);
      };
      std::vector<torch::Tensor> warped(k);
      for (int i = 0; i < k; ++i) {
        warped[i] = WarpFeatures(features[i], context(grids[i], 1)).to(dtype_);
      }
      const torch::Tensor tile_mask = context(warp_mask);
      const BlendOutput out = net_->Blend(
          torch::cat(warped, 0).contiguous(torch::MemoryFormat::ChannelsLast),
          context(valid_depth), tile_mask,
          ulr_log_weights.defined() ? context(ulr_log_weights) : ulr_log_weights);
      target_core(rgb).copy_(core(out.rgb));
      if (out.weights.defined() && out.weights.numel() > 0) {
        have_weights = true;
        target_core(seen_weight)
            .copy_(core((out.weights * tile_mask).sum(0, true).clamp(0.0, 1.0)));
      }
    }
    // [-1,1] -> [0,1]; the net clamps and removes NaN at inference.
    // (TensorToImage brings any device and dtype to a float image on the CPU.)
    result.color = TensorToImage((rgb + 1.0) * 0.5);
    result.coverage = TensorToImage(warp_mask.sum(0, true) > 0);
    result.infinity = AtInfinityMask(result.depth, result.coverage);
    result.confidence = have_weights ? TensorToImage(seen_weight) : result.coverage;
    result.timings.blend_s = timer.Seconds() - result.timings.encode_s;
    return result;
  }

 private:
  // Encoded features of a source view, cached (least recently used out first, within
  // RenderOptions::feature_cache_mb) so a path of targets encodes each source once; and,
  // with RenderOptions::feature_cache_dir, read from and written to disk.
  torch::Tensor Features(const Scene& scene, int view) {
    const auto it = cache_.find(view);
    if (it != cache_.end()) {
      order_.remove(view);
      order_.push_front(view);
      return it->second;
    }
    Timer timer;
    const Image& photo = scene.SourceImage(view);
    torch::Tensor features;
    std::string stored_path;
    if (store_) {
      stored_path = store_->PathFor(photo);
      features = store_->Load(stored_path, config_.EncodedChannels(), photo, dtype_);
      if (features.defined()) {
        features = features.to(device_).contiguous(torch::MemoryFormat::ChannelsLast);
      }
    }
    if (!features.defined()) {
      const torch::Tensor image = (ImageToTensor(photo) * 2.0 - 1.0)
                                      .to(device_, dtype_)
                                      .contiguous(torch::MemoryFormat::ChannelsLast);
      features = net_->Encode(image);
      if (store_) store_->Save(stored_path, features, scene.view(view).name);
    }
    encode_seconds_ += timer.Seconds();
    const int64_t budget = static_cast<int64_t>(options_.feature_cache_mb) << 20;
    while (!order_.empty() && CacheBytes() + Bytes(features) > budget) {
      cache_.erase(order_.back());
      order_.pop_back();
    }
    if (Bytes(features) <= budget) {
      order_.push_front(view);
      cache_.emplace(view, features);
    }
    return features;
  }

  static int64_t Bytes(const torch::Tensor& t) { return t.numel() * t.element_size(); }
  // A few dozen entries at most: summed when needed rather than kept in step.
  int64_t CacheBytes() const {
    int64_t sum = 0;
    for (const auto& [view, features] : cache_) sum += Bytes(features);
    return sum;
  }

  FvsNet net_;
  ModelConfig config_;
  RenderOptions options_;
  torch::Device device_;
  torch::ScalarType dtype_;
  std::unique_ptr<FeatureStore> store_;  // on disk, when options_.feature_cache_dir
  std::map<int, torch::Tensor> cache_;
  std::list<int> order_;
  double encode_seconds_ = 0;
};

}  // namespace

std::string ShippedModelPath(const std::string& variant) {
  namespace fs = std::filesystem;
  std::vector<fs::path> folders;
  if (const char* dir = std::getenv("FVS_MODEL_DIR"); dir && *dir) folders.push_back(dir);
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) folders.push_back(exe.parent_path() / "../share/colmap-fvs/models");
  for (const fs::path& folder : folders) {
    const fs::path file = folder / (variant + ".safetensors");
    if (fs::is_regular_file(file, error)) return file.lexically_normal().string();
  }
  return "";
}

std::string DefaultModelPath(const std::string& variant,
                             const std::string& scene_model_dir, bool* is_scene_model) {
  namespace fs = std::filesystem;
  if (is_scene_model) *is_scene_model = false;
  if (!scene_model_dir.empty()) {
    const fs::path file = fs::path(scene_model_dir) / (variant + ".safetensors");
    std::error_code error;
    if (fs::is_regular_file(file, error)) {
      if (is_scene_model) *is_scene_model = true;
      return file.string();
    }
  }
  return ShippedModelPath(variant);
}

std::unique_ptr<Method> CreateFvsMethod(const std::string& requested,
                                        const RenderOptions& options_in) {
  RenderOptions options = options_in;
  if (options.model_path.empty()) {
    bool scene_model = false;
    options.model_path =
        DefaultModelPath(requested, options.scene_model_dir, &scene_model);
    if (options.model_path.empty()) {
      throw Error("--method " + requested,
                  "method " + requested +
                      " needs model weights: --model_path <weights.safetensors> (no "
                      "shipped " +
                      requested + " model found; models/README.md)");
    }
    std::cerr << (scene_model ? "using the scene's fine-tuned model "
                              : "using the shipped model ")
              << options.model_path
              << (scene_model
                      ? " (view_synthesis_finetune; --model_path for other weights)"
                      : "")
              << "\n";
  }
  ConfigureTorchThreads();
  const bool have_cuda = torch::cuda::is_available();
  if (options.device == "cuda" && !have_cuda) {
    throw Error("--device cuda",
                "no CUDA device: this build's LibTorch has no CUDA or the "
                "machine has no GPU (use --device cpu or auto)");
  }
  const torch::Device device(options.device == "cpu" || !have_cuda ? torch::kCPU
                                                                   : torch::kCUDA);
  if (options.precision == "fp16" && device.is_cpu()) {
    throw Error("--precision fp16",
                "fp16 needs a CUDA device (LibTorch's CPU convolutions have no fp16; "
                "bf16 runs on the CPU)");
  }
  const torch::ScalarType dtype = PrecisionDtype(options.precision);
  ModelConfig config;
  FvsNet net = LoadModel(options.model_path, &config);
  if (requested != "fvs" && requested != config.variant) {
    throw Error(options.model_path, "weights are of variant '" + config.variant +
                                        "', not '" + requested + "'");
  }
  return std::make_unique<FvsMethod>(std::move(net), std::move(config), options, device,
                                     dtype);
}

}  // namespace fvs
