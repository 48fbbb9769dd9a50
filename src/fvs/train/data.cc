#include "fvs/train/data.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "fvs/geometry/warp.h"
#include "fvs/net/image_tensor.h"
#include "fvs/train/train_options.h"
#include "fvs/util/error.h"
#include "fvs/util/hole_filling.h"
#include "fvs/util/safetensors.h"

namespace fvs {
namespace {

constexpr char kSceneFile[] = "scene.safetensors";  // as pack.h (not built everywhere)

torch::Tensor ToTensor(const SafeTensorsFile& file, const std::string& name,
                       SafeDtype dtype, torch::ScalarType type,
                       const std::vector<int64_t>& shape, const std::string& subject) {
  const SafeTensor* t = file.Find(name);
  Require(t != nullptr, subject, "missing tensor '" + name + "'");
  Require(t->dtype == dtype, subject,
          "tensor '" + name + "' must be " + SafeDtypeName(dtype) + ", not " +
              SafeDtypeName(t->dtype));
  bool shape_ok = t->shape.size() == shape.size();
  for (size_t i = 0; shape_ok && i < shape.size(); ++i) {
    shape_ok = shape[i] < 0 || shape[i] == t->shape[i];
  }
  Require(shape_ok, subject, "tensor '" + name + "' has an unexpected shape");
  torch::Tensor out = torch::empty(t->shape, torch::TensorOptions().dtype(type));
  Require(static_cast<size_t>(out.numel() * out.element_size()) == t->data.size(),
          subject, "tensor '" + name + "' has a wrong byte count");
  if (!t->data.empty()) std::memcpy(out.data_ptr(), t->data.data(), t->data.size());
  return out;
}

double DoubleAt(const torch::Tensor& t, int64_t i) { return t.data_ptr<double>()[i]; }

}  // namespace

PackedScene LoadPackedScene(const std::string& folder) {
  const std::string path = folder + "/" + kSceneFile;
  const SafeTensorsFile file = ReadSafeTensors(path);
  PackedScene s;
  s.path = folder;
  auto meta = file.metadata.find("fvs_pack_version");
  Require(meta != file.metadata.end(), path, "not a packed scene (no fvs_pack_version)");
  Require(meta->second == "1", path, "unsupported pack version " + meta->second);
  auto names = file.metadata.find("names");
  Require(names != file.metadata.end(), path, "missing the 'names' metadata");
  try {
    for (const auto& n : nlohmann::json::parse(names->second)) {
      s.names.push_back(n.get<std::string>());
    }
  } catch (const std::exception&) {
    throw Error(path, "the 'names' metadata is not a JSON list of strings");
  }
  const int64_t n = static_cast<int64_t>(s.names.size());
  Require(n >= 1, path, "the scene has no views");
  s.holdout.assign(n, false);
  if (auto origin = file.metadata.find("origin"); origin != file.metadata.end()) {
    try {
      const nlohmann::json o = nlohmann::json::parse(origin->second);
      s.origin = {o.at(0).get<double>(), o.at(1).get<double>(), o.at(2).get<double>()};
    } catch (const std::exception&) {
      throw Error(path, "the 'origin' metadata is not a JSON list of three numbers");
    }
    Require(s.origin.allFinite(), path, "the 'origin' metadata is not finite");
  }
  if (auto held = file.metadata.find("holdout"); held != file.metadata.end()) {
    try {
      for (const auto& h : nlohmann::json::parse(held->second)) {
        const auto it = std::find(s.names.begin(), s.names.end(), h.get<std::string>());
        if (it != s.names.end()) s.holdout[it - s.names.begin()] = true;
      }
    } catch (const std::exception&) {
      throw Error(path, "the 'holdout' metadata is not a JSON list of strings");
    }
  }
  s.images =
      ToTensor(file, "images", SafeDtype::kU8, torch::kUInt8, {n, 3, -1, -1}, path);
  const int64_t h = s.images.size(2), w = s.images.size(3);
  Require(h > 0 && w > 0, path, "empty images");
  s.depths = ToTensor(file, "depths", SafeDtype::kF32, torch::kFloat, {n, h, w}, path);
  s.K = ToTensor(file, "K", SafeDtype::kF64, torch::kDouble, {n, 3, 3}, path);
  s.R = ToTensor(file, "R", SafeDtype::kF64, torch::kDouble, {n, 3, 3}, path);
  s.t = ToTensor(file, "t", SafeDtype::kF64, torch::kDouble, {n, 3}, path);
  s.overlap = ToTensor(file, "overlap", SafeDtype::kF32, torch::kFloat, {n, n}, path);
  Require(
      torch::isfinite(s.depths).all().item<bool>() && (s.depths >= 0).all().item<bool>(),
      path, "depths must be finite and >= 0");
  for (const auto* t : {&s.K, &s.R, &s.t}) {
    Require(torch::isfinite(*t).all().item<bool>(), path, "cameras hold NaN or Inf");
  }
  Require(torch::isfinite(s.overlap).all().item<bool>() &&
              (s.overlap >= 0).all().item<bool>() && (s.overlap <= 1).all().item<bool>(),
          path, "overlap must be in [0, 1]");
  for (int64_t i = 0; i < n; ++i) {
    const double fx = DoubleAt(s.K, i * 9), fy = DoubleAt(s.K, i * 9 + 4);
    Require(fx > 0 && fy > 0, path,
            "view " + s.names[i] + " has a non-positive focal length");
  }
  return s;
}

std::vector<int> SelectTrainingSources(const PackedScene& scene, int target, int k) {
  const int n = scene.num_views();
  Require(target >= 0 && target < n, scene.path, "target view out of range");
  const float* row = scene.overlap.data_ptr<float>() + static_cast<int64_t>(target) * n;
  std::vector<int> order;
  for (int j = 0; j < n; ++j) {
    if (j != target && row[j] > 0 && !scene.holdout[j]) order.push_back(j);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return row[a] > row[b]; });
  if (static_cast<int>(order.size()) > k) order.resize(k);
  return order;
}

bool PackedScene::HoldsViewsOut() const {
  return std::find(holdout.begin(), holdout.end(), true) != holdout.end();
}

bool IsTargetView(const PackedScene& scene, int view, bool holdout_targets) {
  if (holdout_targets && scene.HoldsViewsOut()) return scene.holdout[view];
  return !scene.holdout[view];
}

std::vector<int> ValidationTargets(const PackedScene& scene, int count,
                                   bool holdout_targets) {
  std::vector<int> candidates;
  for (int v = 0; v < scene.num_views(); ++v) {
    if (IsTargetView(scene, v, holdout_targets)) candidates.push_back(v);
  }
  const int n = static_cast<int>(candidates.size());
  count = std::min(n, count);
  std::vector<int> targets;
  for (int i = 0; i < count; ++i) {
    targets.push_back(candidates[static_cast<int64_t>(i) * n / count]);
  }
  return targets;
}

torch::Tensor FillHolesOf(const torch::Tensor& rgb, const torch::Tensor& covered,
                          const torch::Tensor& surface) {
  Image color = TensorToImage(rgb);
  const Image depth = TensorToImage(surface);
  FillHoles(TensorToImage(covered), &depth, &color);
  return ImageToTensor(color).to(rgb.device());
}

PinholeCamera TensorCamera(const torch::Tensor& K, const torch::Tensor& R,
                           const torch::Tensor& t, int64_t width, int64_t height) {
  const torch::Tensor k = K.to(torch::kDouble).cpu().contiguous();
  const torch::Tensor r = R.to(torch::kDouble).cpu().contiguous();
  const torch::Tensor tt = t.to(torch::kDouble).cpu().contiguous();
  PinholeCamera camera;
  camera.width = static_cast<int>(width);
  camera.height = static_cast<int>(height);
  camera.fx = DoubleAt(k, 0);
  camera.cx = DoubleAt(k, 2);
  camera.fy = DoubleAt(k, 4);
  camera.cy = DoubleAt(k, 5);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) camera.R(i, j) = DoubleAt(r, 3 * i + j);
    camera.t[i] = DoubleAt(tt, i);
  }
  return camera;
}

namespace {

// A depth map [h, w] as a 1-channel Image.
Image DepthImage(const torch::Tensor& depth) {
  const torch::Tensor d = depth.to(torch::kFloat).cpu().contiguous();
  Image image(static_cast<int>(d.size(1)), static_cast<int>(d.size(0)), 1);
  std::memcpy(image.data.data(), d.data_ptr<float>(), image.data.size() * sizeof(float));
  return image;
}

// ULR log-weights [K, hw] (UlrLogWeights) at the target's pixels: surface points at
// their depth, the rays of pixels without a surface moved to UlrPointAtInfinity as the
// renderer's UlrSurfacePoint does. The sources as ULR sees them: centres in the target
// frame, -R_rel^T t_rel (relative poses as the warp's), focal lengths sqrt(fx fy).
torch::Tensor TrainingUlrLogWeights(const PinholeCamera& target,
                                    const Image& target_depth,
                                    const std::vector<PinholeCamera>& sources,
                                    const torch::Tensor& valid_warp,
                                    const UlrOptions& settings) {
  UlrSources ulr;
  ulr.target_focal = std::sqrt(target.fx * target.fy);
  for (const PinholeCamera& source : sources) {
    const Eigen::Matrix3d R_rel = source.R * target.R.transpose();
    const Eigen::Vector3d t_rel = source.t - R_rel * target.t;
    ulr.centers.push_back(-(R_rel.transpose() * t_rel));
    ulr.focals.push_back(std::sqrt(source.fx * source.fy));
  }
  const int w = target.width, h = target.height;
  const int64_t n = static_cast<int64_t>(w) * h, k = ulr.size();
  const double far_distance = UlrFarDistance(ulr);
  std::vector<double> points(3 * n);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int64_t i = static_cast<int64_t>(y) * w + x;
      const float raw = target_depth.data[i];
      const bool surface = raw > 0 && std::isfinite(raw);
      const double d = surface ? raw : 1.0;
      Eigen::Vector3d p((x + 0.5 - target.cx) / target.fx * d,
                        (y + 0.5 - target.cy) / target.fy * d, d);
      if (!surface) p = UlrPointAtInfinity(p, far_distance);
      for (int c = 0; c < 3; ++c) points[3 * i + c] = p[c];
    }
  }
  const torch::Tensor sees = valid_warp.reshape({k, n}).contiguous();
  torch::Tensor log_weights = torch::empty({k, n}, torch::kFloat);
  UlrLogWeights(points.data(), n, ulr, sees.data_ptr<float>(), settings,
                log_weights.data_ptr<float>(), /*num_threads=*/1);
  return log_weights;
}

}  // namespace

void SampleWarpOptions::Check() const {
  geometry.Check();
  ulr.Check();
}

SampleWarpOptions SampleWarpOptionsFor(const ModelConfig& config,
                                       double occlusion_tolerance) {
  SampleWarpOptions warp;
  warp.geometry.occlusion_tolerance = occlusion_tolerance;
  warp.geometry.at_infinity = config.inf_depth;
  warp.ulr_log_weights = config.ulr_prior > 0;
  warp.ulr.num_blend = config.ulr_num_blend;
  warp.ulr.resolution_weight = config.ulr_resolution_weight;
  return warp;
}

TrainingWarp ComputeTrainingWarp(
    const torch::Tensor& target_K, const torch::Tensor& target_R,
    const torch::Tensor& target_t, const torch::Tensor& target_depth,
    const torch::Tensor& source_K, const torch::Tensor& source_R,
    const torch::Tensor& source_t, const torch::Tensor& source_depths,
    const SampleWarpOptions& settings) {
  const int64_t h = target_depth.size(0), w = target_depth.size(1);
  const int64_t k = source_K.size(0), sh = source_depths.size(1),
                sw = source_depths.size(2);
  const PinholeCamera target = TensorCamera(target_K, target_R, target_t, w, h);
  const Image depth = DepthImage(target_depth);
  settings.Check();
  const WarpOptions& options = settings.geometry;

  TrainingWarp out;
  out.grid = torch::empty({k, h, w, 2}, torch::kFloat);
  out.valid_depth = torch::empty({1, 1, h, w}, torch::kFloat);
  out.valid_warp = torch::empty({k, 1, h, w}, torch::kFloat);
  out.source_z = torch::empty({k, 1, h, w}, torch::kFloat);
  const size_t n = static_cast<size_t>(h * w);
  std::vector<PinholeCamera> sources;
  for (int64_t s = 0; s < k; ++s) {
    sources.push_back(TensorCamera(source_K[s], source_R[s], source_t[s], sw, sh));
    // The warp in double from the relative poses (geometry/warp.h), the renderer's.
    const WarpMap map = ComputeWarpMap(target, depth, sources.back(),
                                       DepthImage(source_depths[s]), options);
    const Image grid =
        GridSampleCoordinates(map, static_cast<int>(sw), static_cast<int>(sh));
    std::memcpy(out.grid[s].data_ptr<float>(), grid.data.data(), 2 * n * sizeof(float));
    std::memcpy(out.valid_warp[s].data_ptr<float>(), map.valid_warp.data.data(),
                n * sizeof(float));
    std::memcpy(out.source_z[s].data_ptr<float>(), map.source_z.data.data(),
                n * sizeof(float));
    if (s == 0) {
      std::memcpy(out.valid_depth.data_ptr<float>(), map.valid_depth.data.data(),
                  n * sizeof(float));
    }
  }
  if (k == 0) {
    out.valid_depth.copy_(((target_depth > 0) & torch::isfinite(target_depth))
                              .to(torch::kFloat)
                              .reshape({1, 1, h, w}));
  }
  if (settings.ulr_log_weights) {
    out.ulr_log_weights =
        TrainingUlrLogWeights(target, depth, sources, out.valid_warp, settings.ulr)
            .reshape({k, 1, h, w});
  }
  return out;
}

TrainingSample MakeSample(const PackedScene& scene, int target,
                          const std::vector<int>& sources, int x0, int y0, int crop_width,
                          int crop_height, const SampleWarpOptions& settings) {
  using torch::indexing::Slice;
  Require(!sources.empty(), scene.path,
          "target " + scene.names.at(target) + " has no source");
  Require(x0 >= 0 && y0 >= 0 && x0 + crop_width <= scene.width() &&
              y0 + crop_height <= scene.height() && crop_width > 0 && crop_height > 0,
          scene.path, "crop outside the image");
  TrainingSample s;
  s.target = target;
  s.sources = sources;
  s.x0 = x0;
  s.y0 = y0;
  const torch::Tensor idx =
      torch::tensor(std::vector<int64_t>(sources.begin(), sources.end()), torch::kLong);
  const auto ys = Slice(y0, y0 + crop_height), xs = Slice(x0, x0 + crop_width);
  s.target_rgb = scene.images[target]
                     .index({Slice(), ys, xs})
                     .to(torch::kFloat)
                     .div(255.0)
                     .unsqueeze(0)
                     .contiguous();
  s.source_rgb = scene.images.index_select(0, idx).to(torch::kFloat).div(127.5).sub(1.0);
  torch::Tensor K = scene.K[target].clone();
  K[0][2] -= x0;
  K[1][2] -= y0;
  s.warp = ComputeTrainingWarp(
      K, scene.R[target], scene.t[target], scene.depths[target].index({ys, xs}),
      scene.K.index_select(0, idx), scene.R.index_select(0, idx),
      scene.t.index_select(0, idx), scene.depths.index_select(0, idx), settings);
  return s;
}

void CropSourcesToFootprint(TrainingSample* sample, int margin, int multiple) {
  using torch::indexing::Slice;
  Require(margin >= 1 && multiple >= 1, "CropSourcesToFootprint",
          "margin and multiple must be positive");
  const int64_t k = sample->source_rgb.size(0);
  const int64_t height = sample->source_rgb.size(2), width = sample->source_rgb.size(3);
  // Source pixel positions (pixel i spans [i, i+1]) of every target pixel; only positions
  // within a pixel of the image can pick up a non-zero bilinear weight.
  const torch::Tensor grid = sample->warp.grid.to(torch::kDouble);
  const torch::Tensor u = (grid.select(3, 0) + 1) * (0.5 * width);
  const torch::Tensor v = (grid.select(3, 1) + 1) * (0.5 * height);
  const torch::Tensor near = torch::isfinite(u) & torch::isfinite(v) & (u >= -1) &
                             (u <= width + 1) & (v >= -1) & (v <= height + 1);
  std::vector<int64_t> x0(k), y0(k), x1(k), y1(k);
  int64_t box_w = 0, box_h = 0;
  for (int64_t i = 0; i < k; ++i) {
    const torch::Tensor m = near[i];
    if (!m.any().item<bool>()) {
      x0[i] = y0[i] = 0, x1[i] = y1[i] = 1;
      continue;
    }
    const torch::Tensor us = u[i].masked_select(m), vs = v[i].masked_select(m);
    x0[i] = std::max<int64_t>(
        0, static_cast<int64_t>(std::floor(us.min().item<double>())) - margin);
    y0[i] = std::max<int64_t>(
        0, static_cast<int64_t>(std::floor(vs.min().item<double>())) - margin);
    x1[i] = std::min<int64_t>(
        width, static_cast<int64_t>(std::ceil(us.max().item<double>())) + margin);
    y1[i] = std::min<int64_t>(
        height, static_cast<int64_t>(std::ceil(vs.max().item<double>())) + margin);
    box_w = std::max(box_w, x1[i] - x0[i]);
    box_h = std::max(box_h, y1[i] - y0[i]);
  }
  if (box_w == 0) return;
  box_w = std::min<int64_t>(width, (box_w + multiple - 1) / multiple * multiple);
  box_h = std::min<int64_t>(height, (box_h + multiple - 1) / multiple * multiple);
  if (box_w == width && box_h == height) return;
  std::vector<torch::Tensor> crops, grids;
  for (int64_t i = 0; i < k; ++i) {
    const int64_t ox = std::clamp<int64_t>(x0[i], 0, width - box_w);
    const int64_t oy = std::clamp<int64_t>(y0[i], 0, height - box_h);
    crops.push_back(sample->source_rgb[i].index(
        {Slice(), Slice(oy, oy + box_h), Slice(ox, ox + box_w)}));
    grids.push_back(torch::stack(
        {(u[i] - ox) * (2.0 / box_w) - 1, (v[i] - oy) * (2.0 / box_h) - 1}, 2));
  }
  sample->source_rgb = torch::stack(crops).contiguous();
  sample->warp.grid =
      torch::stack(grids).to(sample->warp.grid.scalar_type()).contiguous();
}

void ApplyColorJitter(const ColorJitter& j, TrainingSample* sample) {
  const auto gain = torch::tensor({j.gain[0], j.gain[1], j.gain[2]}, torch::kFloat)
                        .reshape({1, 3, 1, 1});
  auto jitter01 = [&](const torch::Tensor& x) {
    torch::Tensor y = x * gain;
    const torch::Tensor grey = y.mean(1, true);
    y = grey + j.saturation * (y - grey);
    y = (y - 0.5) * j.contrast + 0.5 + j.brightness;
    return y.clamp(0.0, 1.0);
  };
  sample->target_rgb = jitter01(sample->target_rgb);
  sample->source_rgb = jitter01((sample->source_rgb + 1.0) * 0.5) * 2.0 - 1.0;
}

TrainingSampler::TrainingSampler(const std::vector<PackedScene>* scenes,
                                 const SamplerOptions& options, uint64_t seed)
    : scenes_(scenes), options_(options), rng_(seed) {
  for (size_t s = 0; s < scenes->size(); ++s) {
    for (int v = 0; v < (*scenes)[s].num_views(); ++v) {
      if (IsTargetView((*scenes)[s], v, options.holdout_targets) &&
          !SelectTrainingSources((*scenes)[s], v, 1).empty()) {
        targets_.emplace_back(static_cast<int>(s), v);
      }
    }
  }
  Require(!targets_.empty(), "training data",
          "no view of any scene overlaps another view (nothing to train on)");
}

double TrainingSampler::Uniform(double lo, double hi) {
  // Own mapping rather than std::uniform_real_distribution: identical on every library.
  const double unit = static_cast<double>(rng_() >> 11) * (1.0 / 9007199254740992.0);
  return lo + (hi - lo) * unit;
}

TrainingSample TrainingSampler::Next() {
  const auto [scene_index, target] = targets_[rng_() % targets_.size()];
  const PackedScene& scene = (*scenes_)[scene_index];
  const int cw = std::min(options_.crop, scene.width());
  const int ch = std::min(options_.crop, scene.height());
  const int x0 = static_cast<int>(rng_() % static_cast<uint64_t>(scene.width() - cw + 1));
  const int y0 =
      static_cast<int>(rng_() % static_cast<uint64_t>(scene.height() - ch + 1));
  TrainingSample sample = MakeSample(
      scene, target, SelectTrainingSources(scene, target, options_.num_sources), x0, y0,
      cw, ch, options_.warp);
  sample.scene = scene_index;
  if (options_.source_margin >= 0) {
    // Multiple of 4: the encoder's stride, so no padding is added to the crop.
    CropSourcesToFootprint(&sample, std::max(1, options_.source_margin), 4);
  }
  if (options_.augment) {
    ColorJitter j;
    j.brightness = Uniform(-0.08, 0.08);
    j.contrast = Uniform(0.85, 1.15);
    j.saturation = Uniform(0.8, 1.2);
    for (double& g : j.gain) g = Uniform(0.92, 1.08);
    ApplyColorJitter(j, &sample);
  }
  return sample;
}

std::string TrainingSampler::State() const {
  std::ostringstream s;
  s << rng_;
  return s.str();
}

void TrainingSampler::SetState(const std::string& state) {
  std::istringstream s(state);
  std::mt19937_64 rng;
  s >> rng;
  Require(!s.fail(), "checkpoint", "malformed sampler state");
  rng_ = rng;
}

std::vector<PackedScene> LoadPackedScenes(const std::string& list, int min_views, int k) {
  std::vector<PackedScene> scenes;
  for (const std::string& folder : ReadSceneList(list)) {
    PackedScene s = LoadPackedScene(folder);
    Require(s.num_views() >= min_views, folder,
            "has " + std::to_string(s.num_views()) + " views; training with " +
                std::to_string(k) + " sources needs at least " +
                std::to_string(min_views) + " (listed in " + list + ")");
    scenes.push_back(std::move(s));
  }
  return scenes;
}

}  // namespace fvs
