#include "fvs/train/mesh_photo_refine.h"

#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <set>

#include "fvs/geometry/rasterizer.h"
#include "fvs/train/data.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

const char kSubject[] = "view_synthesis_refine";
using torch::indexing::Slice;

// What one rasterisation of the moved mesh fixes until the next: per surface pixel of
// every target, its face, its ray, its sources with their blend weights, its colour.
struct FrozenPixels {
  torch::Tensor target;  // long [P]
  torch::Tensor face;    // long [P]
  torch::Tensor ray;     // double [P,3], target camera frame, z = 1
  torch::Tensor source;  // long [P,K] (0 where unused; its weight is 0)
  torch::Tensor weight;  // double [P,K], rows sum to 1
  torch::Tensor rgb;     // double [P,3] in [0,1], the target photo
  int64_t size() const { return target.defined() ? target.size(0) : 0; }
};

// The scene's cameras as tensors indexed by view.
struct Cameras {
  torch::Tensor R, t;            // double [N,3,3], [N,3]
  torch::Tensor fx, fy, cx, cy;  // double [N]
  int width = 0, height = 0;
};

Cameras MakeCameras(const PackedScene& scene) {
  Cameras c;
  c.R = scene.R.to(torch::kDouble);
  c.t = scene.t.to(torch::kDouble);
  const torch::Tensor K = scene.K.to(torch::kDouble);
  c.fx = K.index({Slice(), 0, 0}).contiguous();
  c.fy = K.index({Slice(), 1, 1}).contiguous();
  c.cx = K.index({Slice(), 0, 2}).contiguous();
  c.cy = K.index({Slice(), 1, 2}).contiguous();
  c.width = scene.width();
  c.height = scene.height();
  return c;
}

TriangleMesh Moved(const TriangleMesh& mesh, const torch::Tensor& offsets) {
  TriangleMesh moved;
  moved.faces = mesh.faces;
  moved.vertices = mesh.vertices;
  const torch::Tensor o = offsets.detach().contiguous();
  const double* d = o.data_ptr<double>();
  for (size_t i = 0; i < moved.vertices.size(); ++i) {
    const Eigen::Vector3d v =
        mesh.vertices[i] + Eigen::Vector3d(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
    if (v.allFinite()) moved.vertices[i] = v;
  }
  return moved;
}

// Rasterises the moved mesh in every view that is a target or a source (all views not
// held out) and freezes, for each target, its surface pixels that some source sees.
FrozenPixels Freeze(const PackedScene& scene, const TriangleMesh& mesh,
                    const std::vector<int>& targets, const torch::Tensor& photos,
                    const MeshPhotoRefineOptions& o) {
  const int n = scene.num_views(), h = scene.height(), w = scene.width();
  torch::Tensor depths = torch::zeros({n, h, w}, torch::kFloat);
  std::vector<std::vector<int32_t>> faces(n);
  RasterizeOptions raster;
  raster.compute_face_ids = true;
  raster.num_threads = o.num_threads;
  for (int v = 0; v < n; ++v) {
    if (scene.holdout[v]) continue;
    const PinholeCamera camera = TensorCamera(scene.K[v], scene.R[v], scene.t[v], w, h);
    RasterResult r = Rasterize(mesh, camera, raster);
    std::memcpy(depths[v].data_ptr<float>(), r.depth.data.data(), sizeof(float) * h * w);
    faces[v] = std::move(r.face_ids);
  }
  SampleWarpOptions settings;
  settings.geometry.occlusion_tolerance = o.occlusion_tolerance;
  settings.geometry.at_infinity = false;
  settings.geometry.num_threads = o.num_threads;
  settings.ulr_log_weights = true;
  const int k = o.num_sources;
  std::vector<torch::Tensor> target, face, ray, source, weight, rgb;
  for (int t : targets) {
    const std::vector<int> sources = SelectTrainingSources(scene, t, k);
    const torch::Tensor idx =
        torch::tensor(std::vector<int64_t>(sources.begin(), sources.end()), torch::kLong);
    const TrainingWarp warp = ComputeTrainingWarp(
        scene.K[t], scene.R[t], scene.t[t], depths[t], scene.K.index_select(0, idx),
        scene.R.index_select(0, idx), scene.t.index_select(0, idx),
        depths.index_select(0, idx), settings);
    const int64_t ks = static_cast<int64_t>(sources.size());
    // Normalised ULR weights of the sources that see the point.
    torch::Tensor wk =
        (warp.ulr_log_weights.reshape({ks, h * w}).to(torch::kDouble).exp() *
         warp.valid_warp.reshape({ks, h * w}).to(torch::kDouble))
            .t();  // [hw, ks]
    const torch::Tensor sum = wk.sum(1);
    const torch::Tensor face_ids =
        torch::from_blob(faces[t].data(), {h * w}, torch::kInt).to(torch::kLong);
    const torch::Tensor keep = ((face_ids >= 0) & (sum > 1e-9)).nonzero().squeeze(1);
    if (keep.numel() == 0) continue;
    wk = wk.index_select(0, keep) / sum.index_select(0, keep).unsqueeze(1);
    torch::Tensor src = idx.unsqueeze(0).expand({keep.size(0), ks});
    if (ks < k) {  // pad to K columns of weight 0
      wk = torch::cat({wk, torch::zeros({keep.size(0), k - ks}, torch::kDouble)}, 1);
      src = torch::cat({src, torch::zeros({keep.size(0), k - ks}, torch::kLong)}, 1);
    }
    const torch::Tensor px = torch::remainder(keep, w).to(torch::kDouble) + 0.5;
    const torch::Tensor py = torch::div(keep, w, "floor").to(torch::kDouble) + 0.5;
    const torch::Tensor Kt = scene.K[t].to(torch::kDouble);
    const double fx = Kt[0][0].item<double>(), fy = Kt[1][1].item<double>();
    const double cx = Kt[0][2].item<double>(), cy = Kt[1][2].item<double>();
    ray.push_back(
        torch::stack({(px - cx) / fx, (py - cy) / fy, torch::ones_like(px)}, 1));
    target.push_back(torch::full({keep.size(0)}, t, torch::kLong));
    face.push_back(face_ids.index_select(0, keep));
    source.push_back(src.contiguous());
    weight.push_back(wk);
    rgb.push_back(photos.index_select(0, keep + int64_t{t} * h * w).to(torch::kDouble));
  }
  Require(!target.empty(), kSubject, "no view of the scene sees its mesh from a source");
  FrozenPixels f;
  f.target = torch::cat(target);
  f.face = torch::cat(face);
  f.ray = torch::cat(ray);
  f.source = torch::cat(source);
  f.weight = torch::cat(weight);
  f.rgb = torch::cat(rgb);
  return f;
}

// Bilinear samples of the photos (flat float [N*H*W,3]) at pixel positions (u, v) of
// views `view` (COLMAP's convention: pixel i spans [i, i+1]); positions outside clamp to
// the border. All [M] tensors; returns double [M,3].
torch::Tensor SampleBilinear(const torch::Tensor& photos, const Cameras& c,
                             const torch::Tensor& view, const torch::Tensor& u,
                             const torch::Tensor& v) {
  const torch::Tensor x = (u - 0.5).clamp(0, c.width - 1);
  const torch::Tensor y = (v - 0.5).clamp(0, c.height - 1);
  const torch::Tensor x0 = x.detach().floor().clamp(0, c.width - 2);
  const torch::Tensor y0 = y.detach().floor().clamp(0, c.height - 2);
  const torch::Tensor ax = (x - x0).unsqueeze(1), ay = (y - y0).unsqueeze(1);
  const torch::Tensor base = view * (int64_t{c.width} * c.height) +
                             y0.to(torch::kLong) * c.width + x0.to(torch::kLong);
  auto at = [&](int64_t offset) {
    return photos.index_select(0, base + offset).to(torch::kDouble);
  };
  return (1 - ay) * ((1 - ax) * at(0) + ax * at(1)) +
         ay * ((1 - ax) * at(c.width) + ax * at(c.width + 1));
}

// The leave-one-out renders of the frozen pixels `pick` with the vertices `vertices`
// (double [V,3]): each pixel's point is its ray's hit on its face's plane, sampled in its
// sources and blended with the frozen weights. Returns double [M,3] and sets *usable
// (double [M]: 1 where the ray meets the plane in front of the camera).
torch::Tensor Render(const FrozenPixels& f, const torch::Tensor& pick,
                     const torch::Tensor& vertices, const torch::Tensor& faces,
                     const Cameras& c, const torch::Tensor& photos,
                     torch::Tensor* usable) {
  const torch::Tensor target = f.target.index_select(0, pick);
  const torch::Tensor ray = f.ray.index_select(0, pick);
  const torch::Tensor corners = faces.index_select(0, f.face.index_select(0, pick));
  const int64_t m = pick.size(0);
  const torch::Tensor tri =
      vertices.index_select(0, corners.reshape({-1})).reshape({m, 3, 3});
  const torch::Tensor R = c.R.index_select(0, target), t = c.t.index_select(0, target);
  // Into the target camera frame: x_cam = R x + t.
  const torch::Tensor cam = torch::einsum("mij,mkj->mki", {R, tri}) + t.unsqueeze(1);
  const torch::Tensor p0 = cam.select(1, 0);
  const torch::Tensor normal =
      torch::cross(cam.select(1, 1) - p0, cam.select(1, 2) - p0, 1);
  const torch::Tensor denom = (normal * ray).sum(1);
  const torch::Tensor numer = (normal * p0).sum(1);
  const torch::Tensor scale = normal.norm(2, 1) * ray.norm(2, 1);
  const torch::Tensor ok_plane = denom.abs() > 1e-9 * scale.detach();
  const torch::Tensor depth =
      numer / torch::where(ok_plane, denom, torch::ones_like(denom));
  const torch::Tensor ok = ok_plane & (depth.detach() > 0);
  const torch::Tensor point_cam =
      ray * torch::where(ok, depth, torch::ones_like(depth)).unsqueeze(1);
  const torch::Tensor world = torch::einsum("mji,mj->mi", {R, point_cam - t});
  torch::Tensor colour = torch::zeros({m, 3}, torch::kDouble);
  for (int64_t s = 0; s < f.source.size(1); ++s) {
    const torch::Tensor view = f.source.select(1, s).index_select(0, pick);
    const torch::Tensor w = f.weight.select(1, s).index_select(0, pick);
    const torch::Tensor xs =
        torch::einsum("mij,mj->mi", {c.R.index_select(0, view), world}) +
        c.t.index_select(0, view);
    const torch::Tensor z = xs.select(1, 2);
    const torch::Tensor in_front = z.detach() > 1e-9;
    const torch::Tensor zs = torch::where(in_front, z, torch::ones_like(z));
    const torch::Tensor u =
        c.fx.index_select(0, view) * xs.select(1, 0) / zs + c.cx.index_select(0, view);
    const torch::Tensor v =
        c.fy.index_select(0, view) * xs.select(1, 1) / zs + c.cy.index_select(0, view);
    const torch::Tensor sample = SampleBilinear(photos, c, view, u, v);
    colour = colour + (w * in_front.to(torch::kDouble)).unsqueeze(1) * sample;
  }
  *usable = ok.to(torch::kDouble);
  return colour;
}

// Per pixel: sqrt(|render - truth|^2 + eps^2) - eps, [M].
torch::Tensor CharbonnierPerPixel(const torch::Tensor& render, const torch::Tensor& truth,
                                  double eps) {
  return ((render - truth).pow(2).sum(1) + eps * eps).sqrt() - eps;
}

// Its mean over the usable pixels.
torch::Tensor Charbonnier(const torch::Tensor& render, const torch::Tensor& truth,
                          const torch::Tensor& usable, double eps) {
  return (CharbonnierPerPixel(render, truth, eps) * usable).sum() /
         usable.sum().clamp_min(1);
}

// Mean Charbonnier error over all frozen pixels, in chunks, without gradients.
double FullError(const FrozenPixels& f, const torch::Tensor& vertices,
                 const torch::Tensor& faces, const Cameras& c,
                 const torch::Tensor& photos, double eps) {
  torch::NoGradGuard no_grad;
  double sum = 0, count = 0;
  const int64_t n = f.size(), chunk = 1 << 18;
  for (int64_t i = 0; i < n; i += chunk) {
    const torch::Tensor pick = torch::arange(i, std::min(n, i + chunk), torch::kLong);
    torch::Tensor usable;
    const torch::Tensor r = Render(f, pick, vertices, faces, c, photos, &usable);
    const torch::Tensor e = CharbonnierPerPixel(r, f.rgb.index_select(0, pick), eps);
    sum += (e * usable).sum().item<double>();
    count += usable.sum().item<double>();
  }
  return count > 0 ? sum / count : 0;
}

// The photos as one flat float [N*H*W,3] table in [0,1], box-blurred with `radius`
// (0: as they are): the coarse levels, where a surface a few pixels off still sees the
// slope of the colour error toward its place.
torch::Tensor FlatPhotos(const PackedScene& scene, int radius) {
  torch::Tensor p = scene.images.to(torch::kFloat).div(255.0);
  if (radius > 0) {
    p = torch::avg_pool2d(p, {2 * radius + 1, 2 * radius + 1}, {1, 1}, {radius, radius},
                          /*ceil_mode=*/false, /*count_include_pad=*/false);
  }
  return p.permute({0, 2, 3, 1}).reshape({-1, 3}).contiguous();
}

struct Edges {
  torch::Tensor a, b;    // long [E]: each undirected edge once
  torch::Tensor degree;  // double [V,1], at least 1
  double median_length = 0;
};

Edges MakeEdges(const TriangleMesh& mesh) {
  std::set<std::pair<int, int>> unique;
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int i = 0; i < 3; ++i) {
      const int p = f[i], q = f[(i + 1) % 3];
      if (p != q) unique.insert({std::min(p, q), std::max(p, q)});
    }
  }
  std::vector<int64_t> a, b;
  std::vector<double> lengths;
  std::vector<double> degree(mesh.vertices.size(), 0.0);
  for (const auto& [p, q] : unique) {
    a.push_back(p);
    b.push_back(q);
    degree[p] += 1;
    degree[q] += 1;
    const double l = (mesh.vertices[p] - mesh.vertices[q]).norm();
    if (std::isfinite(l)) lengths.push_back(l);
  }
  Edges e;
  e.a = torch::tensor(a, torch::kLong);
  e.b = torch::tensor(b, torch::kLong);
  e.degree = torch::tensor(degree, torch::kDouble).clamp_min(1).unsqueeze(1);
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2,
                     lengths.end());
    e.median_length = lengths[lengths.size() / 2];
  }
  return e;
}

// Unit area-weighted vertex normals, double [V,3] (zero where a vertex has no face of
// finite, non-zero area).
torch::Tensor VertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> sum(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d n = (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                                  .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
    if (!n.allFinite()) continue;
    for (int i = 0; i < 3; ++i) sum[f[i]] += n;
  }
  torch::Tensor out = torch::zeros({static_cast<int64_t>(sum.size()), 3}, torch::kDouble);
  double* d = out.data_ptr<double>();
  for (size_t i = 0; i < sum.size(); ++i) {
    const double length = sum[i].norm();
    if (!(length > 0) || !std::isfinite(length)) continue;
    for (int j = 0; j < 3; ++j) d[3 * i + j] = sum[i][j] / length;
  }
  return out;
}

// Mean squared uniform Laplacian of per-vertex values, in median edge lengths squared.
torch::Tensor Roughness(const torch::Tensor& values, const Edges& e) {
  torch::Tensor sum = torch::zeros_like(values);
  sum = sum.index_add(0, e.a, values.index_select(0, e.b));
  sum = sum.index_add(0, e.b, values.index_select(0, e.a));
  const torch::Tensor lap = values - sum / e.degree;
  return lap.pow(2).sum(1).mean() / (e.median_length * e.median_length);
}

}  // namespace

void MeshPhotoRefineOptions::Check() const {
  Require(seconds > 0 && std::isfinite(seconds), kSubject,
          "the time budget must be positive");
  Require(num_sources >= 1, kSubject, "--Refine.num_sources must be at least 1");
  Require(pixels_per_step >= 64, kSubject,
          "--Refine.pixels_per_step must be at least 64");
  Require(step > 0 && std::isfinite(step), kSubject, "--Refine.step must be positive");
  Require(smoothness >= 0 && std::isfinite(smoothness), kSubject,
          "--Refine.smoothness must be at least 0");
  Require(max_move > 0 && std::isfinite(max_move), kSubject,
          "--Refine.max_move must be positive");
  Require(steps_per_raster >= 1, kSubject,
          "--Refine.steps_per_raster must be at least 1");
  Require(coarse_levels >= 0 && coarse_levels <= 6, kSubject,
          "--Refine.coarse_levels must be in [0, 6]");
  Require(charbonnier_eps > 0, kSubject, "the Charbonnier epsilon must be positive");
  Require(occlusion_tolerance > 0, kSubject, "the occlusion tolerance must be positive");
}

MeshPhotoRefineResult RefineMeshByPhotoConsistency(
    const PackedScene& scene, const TriangleMesh& mesh, const MeshPhotoRefineOptions& o,
    const std::vector<Eigen::Vector3d>& initial_offsets) {
  o.Check();
  Timer timer;
  Require(!mesh.faces.empty(), kSubject, "the mesh has no faces");
  Require(initial_offsets.empty() || initial_offsets.size() == mesh.vertices.size(),
          kSubject, "the saved offsets do not match the mesh (its vertex count changed)");
  if (o.num_threads > 0) torch::set_num_threads(o.num_threads);
  torch::manual_seed(o.seed);
  std::vector<int> targets;
  for (int v = 0; v < scene.num_views(); ++v) {
    if (!scene.holdout[v] && !SelectTrainingSources(scene, v, 1).empty())
      targets.push_back(v);
  }
  Require(!targets.empty(), kSubject, "no photo of the scene has a source");
  const Cameras cameras = MakeCameras(scene);
  // Coarse to fine: equal shares of the budget at blur radii 2^L, ..., 2, then sharp.
  const int levels = o.coarse_levels + 1;
  auto radius_of = [&](int level) { return level == 0 ? 0 : 1 << level; };
  int level = o.coarse_levels;
  torch::Tensor photos = FlatPhotos(scene, radius_of(level));
  const torch::Tensor sharp = level == 0 ? photos : FlatPhotos(scene, 0);
  const int64_t nv = static_cast<int64_t>(mesh.vertices.size());
  torch::Tensor base = torch::empty({nv, 3}, torch::kDouble);
  torch::Tensor initial = torch::zeros({nv, 3}, torch::kDouble);
  for (int64_t i = 0; i < nv; ++i) {
    for (int j = 0; j < 3; ++j) {
      base[i][j] = std::isfinite(mesh.vertices[i][j]) ? mesh.vertices[i][j] : 0.0;
      if (!initial_offsets.empty()) initial[i][j] = initial_offsets[i][j];
    }
  }
  // Vertices move along their normals only: a move within the surface changes no render
  // but which face a pixel sees, and drifts where the photos have no say.
  const torch::Tensor normals = VertexNormals(mesh);
  torch::Tensor heights = (initial * normals).sum(1, /*keepdim=*/true);
  std::vector<int64_t> face_data;
  for (const Eigen::Vector3i& f : mesh.faces)
    face_data.insert(face_data.end(), {f[0], f[1], f[2]});
  const torch::Tensor faces = torch::tensor(face_data, torch::kLong).reshape({-1, 3});
  const Edges edges = MakeEdges(mesh);
  Require(edges.median_length > 0, kSubject, "the mesh's edges have no length");
  const double bound = o.max_move * edges.median_length;
  heights.clamp_(-bound, bound);
  heights.requires_grad_(true);
  torch::optim::Adam adam({heights},
                          torch::optim::AdamOptions(o.step * edges.median_length));
  auto offsets = [&] { return heights * normals; };

  MeshPhotoRefineResult result;
  result.num_targets = static_cast<int>(targets.size());
  result.median_edge = edges.median_length;
  FrozenPixels frozen = Freeze(scene, Moved(mesh, offsets()), targets, sharp, o);
  result.initial_error = FullError(frozen, base + offsets().detach(), faces, cameras,
                                   sharp, o.charbonnier_eps);
  // The first level's colours (the sharp ones are frozen already without blurred levels).
  if (level > 0) frozen = Freeze(scene, Moved(mesh, offsets()), targets, photos, o);
  // The final error and the last rasterisation take about what the first did.
  const double reserve = 2 * timer.Seconds();
  const double start = timer.Seconds();
  double last_report = 0, last_checkpoint = 0;
  while (timer.Seconds() + reserve < o.seconds && !(o.stop && o.stop())) {
    // The level this share of the budget is for.
    const double share =
        (timer.Seconds() - start) / std::max(1e-9, o.seconds - reserve - start);
    const int want = std::max(0, o.coarse_levels - static_cast<int>(share * levels));
    if (want != level) {
      level = want;
      photos = level == 0 ? sharp : FlatPhotos(scene, radius_of(level));
      frozen = Freeze(scene, Moved(mesh, offsets()), targets, photos, o);
    } else if (result.steps > 0 && result.steps % o.steps_per_raster == 0) {
      frozen = Freeze(scene, Moved(mesh, offsets()), targets, photos, o);
    }
    const torch::Tensor pick = torch::randint(
        frozen.size(), {std::min<int64_t>(o.pixels_per_step, frozen.size())},
        torch::kLong);
    adam.zero_grad();
    torch::Tensor usable;
    const torch::Tensor render =
        Render(frozen, pick, base + offsets(), faces, cameras, photos, &usable);
    const torch::Tensor photo =
        Charbonnier(render, frozen.rgb.index_select(0, pick), usable, o.charbonnier_eps);
    const torch::Tensor loss = photo + o.smoothness * Roughness(heights, edges);
    loss.backward();
    // A face with a vertex near the float limits overflows: its pixels give no direction.
    heights.mutable_grad().nan_to_num_(0.0, 0.0, 0.0);
    adam.step();
    {
      torch::NoGradGuard no_grad;
      heights.clamp_(-bound, bound);
      heights.nan_to_num_(0.0, 0.0, 0.0);
    }
    ++result.steps;
    if (o.checkpoint && timer.Seconds() - last_checkpoint > o.checkpoint_seconds) {
      last_checkpoint = timer.Seconds();
      o.checkpoint(Moved(mesh, offsets()), result.steps);
    }
    if (!o.quiet && timer.Seconds() - last_report > 10) {
      last_report = timer.Seconds();
      std::cerr << "[refine] step " << result.steps << "  photo error " << std::fixed
                << std::setprecision(4) << photo.item<double>() << "  "
                << std::setprecision(0) << timer.Seconds() << " s of " << o.seconds
                << " s\n";
    }
  }
  frozen = Freeze(scene, Moved(mesh, offsets()), targets, sharp, o);
  result.final_error = FullError(frozen, base + offsets().detach(), faces, cameras, sharp,
                                 o.charbonnier_eps);
  result.mesh = Moved(mesh, offsets());
  result.mesh.colors = mesh.colors;
  const torch::Tensor moves = heights.detach().abs().squeeze(1) / edges.median_length;
  result.median_move = moves.median().item<double>();
  result.max_move = moves.max().item<double>();
  result.seconds = timer.Seconds();
  return result;
}

}  // namespace fvs
