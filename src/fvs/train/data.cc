#include "fvs/train/data.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "fvs/net/image_tensor.h"
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

std::vector<int> ValidationTargets(const PackedScene& scene, int count) {
  std::vector<int> candidates;
  for (int v = 0; v < scene.num_views(); ++v) {
    if (!scene.holdout[v]) candidates.push_back(v);
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

namespace {

// The source depth [K, hw] at the source pixels (xx, yy) (whole numbers held as doubles).
torch::Tensor GatherDepth(const torch::Tensor& depths, int64_t width,
                          const torch::Tensor& yy, const torch::Tensor& xx) {
  return torch::gather(depths, 1, (yy * width + xx).to(torch::kLong));
}

// The occlusion tests of scene/warp.h on [K, hw] source positions (u, v) inside the
// sources: for a target surface point at source depth z, the source depth at the nearest
// pixel (no surface = invalid_depth) or interpolated between the 4 nearest pixel centres
// when all 4 are surface; for a pixel at infinity, no surface at the nearest pixel.
torch::Tensor SourceSees(const torch::Tensor& depths, int64_t sw, int64_t sh,
                         const torch::Tensor& u, const torch::Tensor& v,
                         const torch::Tensor& z, const torch::Tensor& surface,
                         const WarpSettings& settings) {
  const double tol = settings.occlusion_tolerance;
  const torch::Tensor sx = torch::clamp(u.floor(), 0, sw - 1);
  const torch::Tensor sy = torch::clamp(v.floor(), 0, sh - 1);
  const torch::Tensor nearest = GatherDepth(depths, sw, sy, sx);
  const torch::Tensor sees_infinity = nearest <= 0;
  const torch::Tensor ds = torch::where(
      nearest > 0, nearest, torch::full_like(nearest, settings.invalid_depth));
  const torch::Tensor nearest_ok = (z - ds).abs() <= tol * z;
  // Or the depth interpolated between the 4 nearest pixel centres when all 4 are surface
  // (a surface seen at a grazing angle changes by more than 1% within one pixel).
  const torch::Tensor fxs = torch::clamp(u - 0.5, 0.0, sw - 1.0);
  const torch::Tensor fys = torch::clamp(v - 0.5, 0.0, sh - 1.0);
  const torch::Tensor x0 = torch::clamp_max(fxs.floor(), std::max<int64_t>(sw - 2, 0));
  const torch::Tensor y0 = torch::clamp_max(fys.floor(), std::max<int64_t>(sh - 2, 0));
  const torch::Tensor x1 = torch::clamp_max(x0 + 1, sw - 1),
                      y1 = torch::clamp_max(y0 + 1, sh - 1);
  const torch::Tensor ax = fxs - x0, ay = fys - y0;
  const torch::Tensor d00 = GatherDepth(depths, sw, y0, x0),
                      d10 = GatherDepth(depths, sw, y0, x1),
                      d01 = GatherDepth(depths, sw, y1, x0),
                      d11 = GatherDepth(depths, sw, y1, x1);
  const torch::Tensor all_surface = (d00 > 0) & (d10 > 0) & (d01 > 0) & (d11 > 0);
  const torch::Tensor bilinear =
      (1 - ay) * ((1 - ax) * d00 + ax * d10) + ay * ((1 - ax) * d01 + ax * d11);
  const torch::Tensor bilinear_ok = all_surface & ((z - bilinear).abs() <= tol * z);
  return torch::where(surface, nearest_ok | bilinear_ok, sees_infinity);
}

// The sources as ULR sees them: centres in the target frame, -R_rel^T t_rel, and focal
// lengths sqrt(fx fy) [K].
UlrSources TrainingUlrSources(const torch::Tensor& R_rel, const torch::Tensor& t_rel,
                              const torch::Tensor& focals, double target_focal) {
  const torch::Tensor centers =
      -torch::matmul(R_rel.transpose(1, 2), t_rel.unsqueeze(-1)).squeeze(-1);
  UlrSources ulr;
  ulr.target_focal = target_focal;
  for (int64_t s = 0; s < centers.size(0); ++s) {
    ulr.centers.emplace_back(centers[s][0].item<double>(), centers[s][1].item<double>(),
                             centers[s][2].item<double>());
    ulr.focals.push_back(focals[s].item<double>());
  }
  return ulr;
}

// ULR log-weights [K, hw] (UlrLogWeights) at the target's points [hw,3]: surface points
// as they are, the rays of pixels without a surface (surface [hw], bool) moved to
// UlrPointAtInfinity as the renderer's UlrSurfacePoint does.
torch::Tensor TrainingUlrLogWeights(const torch::Tensor& points,
                                    const torch::Tensor& surface,
                                    const UlrSources& sources,
                                    const torch::Tensor& valid_warp,
                                    const UlrSettings& settings) {
  const int64_t n = points.size(0), k = sources.size();
  std::vector<double> pts(points.data_ptr<double>(), points.data_ptr<double>() + 3 * n);
  const double far_distance = UlrFarDistance(sources);
  const bool* is_surface = surface.data_ptr<bool>();
  for (int64_t i = 0; i < n; ++i) {
    if (is_surface[i]) continue;
    const Eigen::Vector3d p = UlrPointAtInfinity(
        Eigen::Vector3d(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]), far_distance);
    for (int c = 0; c < 3; ++c) pts[3 * i + c] = p[c];
  }
  const torch::Tensor sees = valid_warp.reshape({k, n}).contiguous();
  torch::Tensor log_weights = torch::empty({k, n}, torch::kFloat);
  UlrLogWeights(pts.data(), n, sources, sees.data_ptr<float>(), settings,
                log_weights.data_ptr<float>(), /*num_threads=*/1);
  return log_weights;
}

}  // namespace

TrainingWarp ComputeTrainingWarp(
    const torch::Tensor& target_K, const torch::Tensor& target_R,
    const torch::Tensor& target_t, const torch::Tensor& target_depth,
    const torch::Tensor& source_K, const torch::Tensor& source_R,
    const torch::Tensor& source_t, const torch::Tensor& source_depths,
    const WarpSettings& settings) {
  using torch::indexing::Slice;
  const auto f64 = torch::TensorOptions().dtype(torch::kDouble);
  const int64_t h = target_depth.size(0), w = target_depth.size(1);
  const int64_t k = source_K.size(0), sh = source_depths.size(1),
                sw = source_depths.size(2);

  // Target rays through the pixel centres, in double.
  const torch::Tensor Kt = target_K.to(torch::kDouble).cpu();
  const double fx = Kt[0][0].item<double>(), fy = Kt[1][1].item<double>();
  const double cx = Kt[0][2].item<double>(), cy = Kt[1][2].item<double>();
  const torch::Tensor xs = (torch::arange(w, f64) + 0.5 - cx) / fx;
  const torch::Tensor ys = (torch::arange(h, f64) + 0.5 - cy) / fy;
  const torch::Tensor raw = target_depth.to(torch::kDouble).cpu();
  const torch::Tensor surface = (raw > 0) & torch::isfinite(raw);
  const torch::Tensor surface_flat = surface.reshape({1, h * w});
  // Surface pixels at their depth; the others as their ray (x, y, 1), warped at
  // infinity: rotated, never translated (scene/warp.h).
  const torch::Tensor depth = torch::where(surface, raw, torch::ones_like(raw));
  const torch::Tensor points =
      torch::stack({xs.unsqueeze(0).expand({h, w}) * depth,
                    ys.unsqueeze(1).expand({h, w}) * depth, depth},
                   -1)
          .reshape({1, h * w, 3});

  // Relative poses R_k R_t^T, t_k - R_rel t_t: absolute translations never meet floats.
  const torch::Tensor Rt = target_R.to(torch::kDouble).cpu();
  const torch::Tensor tt = target_t.to(torch::kDouble).cpu();
  const torch::Tensor Rs = source_R.to(torch::kDouble).cpu();
  const torch::Tensor R_rel = torch::matmul(Rs, Rt.t());  // [K,3,3]
  const torch::Tensor t_rel =
      source_t.to(torch::kDouble).cpu() -
      torch::matmul(R_rel, tt.reshape({3, 1})).squeeze(-1);  // [K,3]
  const torch::Tensor translated = surface_flat.unsqueeze(-1).to(torch::kDouble);
  const torch::Tensor X = torch::matmul(points, R_rel.transpose(1, 2)) +
                          t_rel.unsqueeze(1) * translated;  // [K,hw,3]
  const torch::Tensor z = X.select(2, 2);
  const torch::Tensor norm = X.norm(2, 2);
  const torch::Tensor in_front = z > 1e-12 * torch::clamp_min(norm, 1.0);
  const torch::Tensor Ks = source_K.to(torch::kDouble).cpu();
  const torch::Tensor sfx = Ks.index({Slice(), 0, 0}).unsqueeze(1);
  const torch::Tensor sfy = Ks.index({Slice(), 1, 1}).unsqueeze(1);
  const torch::Tensor scx = Ks.index({Slice(), 0, 2}).unsqueeze(1);
  const torch::Tensor scy = Ks.index({Slice(), 1, 2}).unsqueeze(1);
  const torch::Tensor safe_z = torch::where(in_front, z, torch::ones_like(z));
  torch::Tensor u = sfx * X.select(2, 0) / safe_z + scx;
  torch::Tensor v = sfy * X.select(2, 1) / safe_z + scy;
  const torch::Tensor projects = in_front & torch::isfinite(u) & torch::isfinite(v);
  // As the CPU warp: far-off coordinates stay finite and clearly outside; no projection
  // -> (-1, -1).
  const double lim = 1e7 + 4.0 * std::max(sw, sh);
  u = torch::where(projects, torch::clamp(torch::nan_to_num(u), -lim, lim),
                   torch::full_like(u, -1.0));
  v = torch::where(projects, torch::clamp(torch::nan_to_num(v), -lim, lim),
                   torch::full_like(v, -1.0));
  const torch::Tensor inside = projects & (u >= 0) & (v >= 0) & (u < sw) & (v < sh);
  const torch::Tensor sd = source_depths.to(torch::kDouble).cpu().reshape({k, sh * sw});
  torch::Tensor valid =
      inside & SourceSees(sd, sw, sh, u, v, z, surface_flat.expand({k, h * w}), settings);
  if (!settings.inf_depth) {
    valid = valid & surface_flat;
    u = torch::where(surface_flat, u, torch::full_like(u, -1.0));
    v = torch::where(surface_flat, v, torch::full_like(v, -1.0));
  }

  TrainingWarp out;
  out.grid = torch::stack({2.0 * u / sw - 1.0, 2.0 * v / sh - 1.0}, -1)
                 .reshape({k, h, w, 2})
                 .to(torch::kFloat);
  out.valid_depth = surface.to(torch::kFloat).reshape({1, 1, h, w});
  out.valid_warp = valid.to(torch::kFloat).reshape({k, 1, h, w});
  if (settings.ulr_log_weights) {
    const UlrSources ulr = TrainingUlrSources(
        R_rel, t_rel, torch::sqrt(sfx * sfy).reshape({k}), std::sqrt(fx * fy));
    out.ulr_log_weights = TrainingUlrLogWeights(points.reshape({h * w, 3}).contiguous(),
                                                surface.reshape({h * w}).contiguous(),
                                                ulr, out.valid_warp, settings.ulr)
                              .reshape({k, 1, h, w});
  }
  return out;
}

TrainingSample MakeSample(const PackedScene& scene, int target,
                          const std::vector<int>& sources, int x0, int y0, int crop_width,
                          int crop_height, const WarpSettings& settings) {
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
      if (!(*scenes)[s].holdout[v] && !SelectTrainingSources((*scenes)[s], v, 1).empty()) {
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

}  // namespace fvs
