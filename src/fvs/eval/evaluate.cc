#include "fvs/eval/evaluate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "colmap_ext/image_io.h"
#include "fvs/eval/draw.h"
#include "fvs/eval/metrics.h"
#include "fvs/eval/view_journal.h"
#include "fvs/geometry/warp.h"
#include "fvs/render/targets.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/parse_int.h"
#include "fvs/util/progress.h"

namespace fvs::eval {
namespace {

std::string FormatScale(double scale) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", scale);
  return text;
}

// The flat name without its extension (the contact sheet's PNGs).
std::string FileStem(const std::string& name) {
  const std::string stem = FlatImageName(name);
  const size_t dot = stem.rfind('.');
  return dot == std::string::npos || dot == 0 ? stem : stem.substr(0, dot);
}

Image Thumbnail(const Image& image, int width) {
  const int height =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(width) * image.height /
                                               std::max(1, image.width))));
  return ResizeImage(image, width, height);
}

// ViewResult's mesh_pixels, infinity_pixels and filled_pixels of a render (n/a when the
// method gave no coverage).
void CountPixelOrigins(const RenderResult& result, ViewResult* r) {
  const size_t n = result.coverage.data.size();
  if (n == 0) return;
  const bool have_infinity = result.infinity.data.size() == n;
  double covered = 0, at_infinity = 0;
  for (size_t i = 0; i < n; ++i) {
    covered += result.coverage.data[i] > 0;
    at_infinity += have_infinity && result.infinity.data[i] > 0;
  }
  r->mesh_pixels = (covered - at_infinity) / n;
  r->infinity_pixels = at_infinity / n;
  r->filled_pixels = 1.0 - covered / n;
}

// The share of the render's pixels that no used source covered (filled) although some
// source the target may use sees them: their surface point passes a source's occlusion
// test (geometry/warp.h), or, without a surface, a source sees the direction at infinity.
// What a better choice of sources could still cover; the rest no photo sees.
double FilledButSeenShare(const Scene& scene, const PinholeCamera& target,
                          const std::vector<int>& excluded, const RenderResult& result) {
  const Image& depth = result.depth;
  const Image& coverage = result.coverage;
  if (depth.width != target.width || depth.height != target.height ||
      coverage.data.size() != depth.data.size() || depth.data.empty()) {
    return kNotAvailable;
  }
  const std::set<int> skip(excluded.begin(), excluded.end());
  std::vector<int> allowed;
  for (int i = 0; i < scene.num_views(); ++i) {
    if (!skip.count(i)) allowed.push_back(i);
  }
  const WarpOptions warp;
  int64_t seen = 0;
  for (int y = 0; y < depth.height; ++y) {
    for (int x = 0; x < depth.width; ++x) {
      if (coverage.at(x, y) > 0) continue;
      const double d = depth.at(x, y);
      const bool surface = d > 0 && std::isfinite(d);
      const Eigen::Vector3d ray =
          target.R.transpose() * target.PixelToCamera(x + 0.5, y + 0.5, 1);
      const Eigen::Vector3d point = target.Unproject(x + 0.5, y + 0.5, surface ? d : 1);
      for (int i : allowed) {
        const PinholeCamera& source = scene.view(i).camera;
        const Eigen::Vector3d xc =
            surface ? source.WorldToCamera(point) : source.R * ray;  // infinity: rotation
        if (!(xc.z() > 0)) continue;
        const Eigen::Vector2d uv = source.CameraToPixel(xc);
        if (!(uv.x() >= 0 && uv.y() >= 0 && uv.x() < source.width &&
              uv.y() < source.height))
          continue;
        const Image& source_depth = scene.SourceDepth(i);
        if (surface ? SourceSeesDepth(source_depth, uv.x(), uv.y(), xc.z(),
                                      warp.occlusion_tolerance, warp.invalid_depth)
                    : SourceSeesInfinity(source_depth, uv.x(), uv.y())) {
          ++seen;
          break;
        }
      }
    }
  }
  return static_cast<double>(seen) / depth.data.size();
}

}  // namespace

std::string FormatNumSources(int num_sources) {
  return num_sources == 0 ? "auto" : std::to_string(num_sources);
}

int ParseNumSources(const std::string& text, const std::string& where) {
  if (text == "auto") return 0;
  int k = 0;
  Require(ParsePositiveInt(text, &k), where,
          "'" + text + "' is not a number of sources (a positive integer or auto)");
  return k;
}

std::string EvalConfig::Label() const {
  std::string label =
      method + " K=" + FormatNumSources(num_sources) + " s=" + FormatScale(scale);
  if (precision != "fp32") label += " " + precision;
  return label;
}

std::string EvalConfig::Slug() const {
  std::string slug =
      method + "_k" + FormatNumSources(num_sources) + "_s" + FormatScale(scale);
  if (precision != "fp32") slug += "_" + precision;
  for (char& c : slug) {
    if (c == '.') c = 'p';
  }
  return slug;
}

void PreloadPhotos(const Scene& scene,
                   std::vector<std::pair<int, std::string>>* bad_photos) {
  bad_photos->clear();
  for (int i = 0; i < scene.num_views(); ++i) {
    try {
      scene.SourceImage(i);
    } catch (const std::exception& e) {
      bad_photos->emplace_back(i, e.what());
    }
  }
}

namespace {

// The sources no target may use: the withheld set and photos that cannot be read.
std::vector<int> SharedExcludedSources(
    const Scene& scene, const TargetSet& set,
    const std::vector<std::pair<int, std::string>>& bad_photos) {
  std::vector<int> excluded;
  std::set<int> bad;
  for (const auto& [index, error] : bad_photos) {
    excluded.push_back(index);
    bad.insert(index);
  }
  for (const std::string& name : set.excluded_sources) {
    const int index = scene.FindView(name);
    if (index >= 0 && !bad.count(index)) excluded.push_back(index);
  }
  return excluded;
}

// Renders the target of `r` (index `index` in the scene) and fills in its scores;
// *thumbnail gets the render's thumbnail when thumbnails are asked for. Throws for a
// view that cannot be evaluated.
void EvaluateView(const Scene& scene, int index, const std::vector<int>& excluded,
                  const EvalConfig& config, const EvalRunOptions& options, Method* method,
                  ViewResult* r, Image* thumbnail) {
  const Image& truth = scene.SourceImage(index);  // throws for a bad photo
  r->width = truth.width;
  r->height = truth.height;
  TargetView view;
  view.name = r->target;
  view.camera = ResizeTarget(scene.view(index).camera, 0, 0, config.scale);
  view.exclude_views = excluded;
  view.exclude_views.push_back(index);

  Timer timer;
  const double cpu_start = ProcessCpuSeconds();
  const RenderResult result = method->Render(scene, view);
  Image prediction = result.color;
  if (prediction.width != truth.width || prediction.height != truth.height) {
    prediction = ResizeImage(prediction, truth.width, truth.height);
  }
  r->seconds = timer.Seconds();
  r->cpu_seconds = ProcessCpuSeconds() - cpu_start;
  prediction = QuantizeTo8Bit(prediction);

  r->psnr = Psnr(prediction, truth);
  r->ssim = Ssim(prediction, truth);
  if (options.lpips) r->lpips = options.lpips(prediction, truth);
  Image covered_mask = result.coverage;
  if (covered_mask.width != truth.width || covered_mask.height != truth.height) {
    covered_mask = ResizeImage(covered_mask, truth.width, truth.height);
  }
  try {
    r->psnr_covered = Psnr(prediction, truth, &covered_mask);
    r->ssim_covered = Ssim(prediction, truth, &covered_mask);
  } catch (const Error&) {
    // Nothing covered: the covered-only numbers do not exist.
  }
  r->sources_used = static_cast<int>(result.sources.size());
  double covered = 0;
  for (float c : result.coverage.data) covered += c;
  r->coverage = covered / std::max<size_t>(1, result.coverage.data.size());
  CountPixelOrigins(result, r);
  r->filled_seen_pixels =
      FilledButSeenShare(scene, view.camera, view.exclude_views, result);
  Require(std::isfinite(r->psnr) && std::isfinite(r->ssim), r->target,
          "metrics are not finite (NaN or Inf in the rendered image)");
  if (!options.write_images_dir.empty()) {
    colmap::WriteImage(options.write_images_dir + "/" + config.Slug() + "/" +
                           FileStem(r->target) + ".png",
                       prediction);
  }
  if (options.thumbnail_width > 0) {
    *thumbnail = Thumbnail(prediction, options.thumbnail_width);
  }
}

void MarkFailed(const std::string& error, ViewResult* r) {
  r->error = error;
  r->psnr = r->ssim = r->lpips = r->seconds = r->cpu_seconds = r->coverage =
      kNotAvailable;
  r->mesh_pixels = r->infinity_pixels = r->filled_pixels = kNotAvailable;
  r->psnr_covered = r->ssim_covered = kNotAvailable;
}

// The rows of `targets` before rendering: what the protocol says of each, and the result
// a journal kept of an earlier run (then `resumed`).
struct PlannedView {
  ViewResult row;
  int index = -1;  // in the scene
  bool resumed = false;
  Image thumbnail;
};

std::vector<PlannedView> PlanViews(const Scene& scene, const TargetSet& set,
                                   const std::vector<EvalTarget>& targets,
                                   const EvalConfig& config,
                                   const EvalRunOptions& options) {
  std::vector<PlannedView> views;
  for (const EvalTarget& target : targets) {
    PlannedView v;
    ViewResult& r = v.row;
    r.scene = options.scene_name;
    r.config = config;
    r.protocol = set.protocol;
    r.target = target.name;
    r.geometry_holdout = target.geometry_holdout;
    r.error = target.error;
    r.skipped = target.skipped;
    v.index = r.ok() ? scene.FindView(target.name) : -1;
    if (r.ok() && v.index < 0) r.error = "not a registered image of the model";
    if (r.ok() && options.journal) {
      v.resumed = options.journal->Find(
          config, target.name, &r, options.thumbnail_width > 0 ? &v.thumbnail : nullptr);
    }
    views.push_back(std::move(v));
  }
  return views;
}

}  // namespace

std::string FlatImageName(const std::string& name) {
  std::string flat = name;
  for (char& c : flat) {
    if (c == '/' || c == '\\' || c == ' ') c = '_';
  }
  return flat;
}

std::vector<ViewResult> EvaluateTargets(
    const Scene& scene, const TargetSet& set, const std::vector<EvalTarget>& targets,
    const EvalConfig& config, const EvalRunOptions& options,
    const std::vector<std::pair<int, std::string>>& bad_photos,
    std::vector<ViewThumbnails>* thumbnails) {
  RenderOptions render = options.render;
  render.num_sources = config.num_sources;
  render.model_path = config.model_path;
  render.precision = config.precision;
  std::unique_ptr<Method> method = CreateMethod(config.method, render);
  const std::vector<int> excluded = SharedExcludedSources(scene, set, bad_photos);
  if (!options.write_images_dir.empty()) {
    std::filesystem::create_directories(options.write_images_dir + "/" + config.Slug());
  }

  std::vector<PlannedView> views = PlanViews(scene, set, targets, config, options);
  const int64_t num_resumed = std::count_if(
      views.begin(), views.end(), [](const PlannedView& v) { return v.resumed; });
  if (num_resumed > 0) {
    std::printf(
        "resuming: %lld of %zu views of %s already evaluated in %s (--overwrite 1 "
        "evaluates them again)\n",
        static_cast<long long>(num_resumed), views.size(), config.Label().c_str(),
        options.journal->dir().c_str());
  }
  std::unique_ptr<Progress> progress;
  if (options.show_progress) {
    progress = std::make_unique<Progress>(
        "evaluate " + config.Label(), static_cast<int64_t>(views.size()) - num_resumed);
  }
  std::vector<ViewResult> results;
  for (PlannedView& v : views) {
    ViewResult& r = v.row;
    if (r.ok() && !v.resumed) {
      try {
        EvaluateView(scene, v.index, excluded, config, options, method.get(), &r,
                     &v.thumbnail);
        if (options.journal) options.journal->Record(r, v.thumbnail);
      } catch (const std::exception& e) {
        MarkFailed(e.what(), &r);
      }
    }
    if (r.ok() && thumbnails && options.thumbnail_width > 0 && !v.thumbnail.empty()) {
      thumbnails->push_back(
          {r.target, v.thumbnail,
           Thumbnail(scene.SourceImage(v.index), options.thumbnail_width)});
    }
    if (!r.ok()) {
      std::fprintf(stderr, "WARNING: %s [%s]: %s%s\n", r.target.c_str(),
                   config.Label().c_str(), r.skipped ? "skipped: " : "", r.error.c_str());
    }
    if (progress && !v.resumed) progress->Advance();
    results.push_back(std::move(r));
  }
  if (progress) progress->Finish();
  return results;
}

}  // namespace fvs::eval
