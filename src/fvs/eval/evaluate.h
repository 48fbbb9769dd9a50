// Renders the targets of a protocol with one method configuration and scores them
// against the photos: PSNR, SSIM (and LPIPS when its weights were given), the wall time
// of each view, and the sources actually used. Predictions are quantised to 8 bits
// first (the paper's protocol); a target rendered at a reduced resolution scale is
// upsampled (bilinear) to the photo's size, so that every configuration answers the same
// question: how close to the photo, at what cost.
//
// One bad view never stops the others: its row carries the error (a photo of the wrong
// size, a name not in the model, a render that failed), and a photo that cannot be read
// is also kept out of every target's sources.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "fvs/eval/protocol.h"
#include "fvs/render/method.h"
#include "fvs/util/image.h"

namespace fvs {
class Scene;
}

namespace fvs::eval {

class ViewJournal;

// One point of an evaluation (or of a sweep): method, K, resolution scale, precision.
struct EvalConfig {
  std::string method = "ulr";
  int num_sources = 0;  // 0 = adaptive (RenderOptions::num_sources)
  double scale = 1.0;
  // The renderer computes in float32 on the CPU; the column exists so that results of
  // other precisions (GPU fp16) merge into the same tables.
  std::string precision = "fp32";
  std::string model_path;  // network methods

  // "ulr K=5 s=1", unique per (method, K, scale, precision).
  std::string Label() const;
  // A file-name-safe form of Label(): "ulr_k5_s1".
  std::string Slug() const;
};

// K as the tables write it: the number, or "auto" for 0 (adaptive).
std::string FormatNumSources(int num_sources);
// The inverse; throws fvs::Error naming `where` for anything else.
int ParseNumSources(const std::string& text, const std::string& where);

constexpr double kNotAvailable = std::numeric_limits<double>::quiet_NaN();

struct ViewResult {
  std::string scene;
  EvalConfig config;
  std::string protocol;
  std::string target;
  bool geometry_holdout = false;
  std::string error;     // empty: evaluated
  bool skipped = false;  // not evaluated for the reason in `error`, not a failure
  double psnr = kNotAvailable;
  double ssim = kNotAvailable;
  double lpips = kNotAvailable;  // NaN: not available (no weights), never a guess
  // The same over the pixels some source contributed to (diagnostic: where the proxy
  // geometry has no surface, e.g. the sky, no method has anything to show). n/a when
  // nothing is covered. The protocol's numbers are the full-image ones above.
  double psnr_covered = kNotAvailable;
  double ssim_covered = kNotAvailable;
  double seconds = kNotAvailable;  // wall time of the render (+ upsampling)
  // CPU seconds of the process (all threads) over the same span: on a shared machine the
  // wall time depends on the load, the CPU time much less.
  double cpu_seconds = kNotAvailable;
  int sources_used = 0;
  double coverage = kNotAvailable;  // fraction of pixels some source contributed to
  // Where the pixels came from, as fractions of the rendered pixels (they sum to 1):
  // blended from the sources' view of the mesh's surface, from the background the
  // sources see at infinity beyond the mesh (RenderResult::infinity), and from neither
  // (no source sees them: filled by push-pull, or black with --fill_holes 0).
  double mesh_pixels = kNotAvailable;
  double infinity_pixels = kNotAvailable;
  double filled_pixels = kNotAvailable;
  // Of the filled pixels, those some source the target may use sees (the surface point
  // passes its occlusion test, or it sees the direction at infinity): what a better
  // choice of sources could still cover, as a fraction of all pixels. Issue 39's bar.
  double filled_seen_pixels = kNotAvailable;
  int width = 0, height = 0;  // the photo's size (metrics are computed at it)

  bool ok() const { return error.empty(); }
  bool failed() const { return !ok() && !skipped; }

  // The measured fields above, psnr to height, in results.csv's column order, each with
  // the decimals the CSV keeps (0 for the ints): results.csv (report.cc) and the view
  // journal (view_journal.cc) write and read them through this list, so a new number is
  // its declaration plus one line here. (Self: ViewResult or const ViewResult; visit
  // takes (name, double& or int&, decimals).)
  template <typename Self, typename Visit>
  static void ForEachMeasure(Self& r, Visit&& visit) {
    visit("psnr", r.psnr, 4);
    visit("ssim", r.ssim, 5);
    visit("lpips", r.lpips, 5);
    visit("psnr_covered", r.psnr_covered, 4);
    visit("ssim_covered", r.ssim_covered, 5);
    visit("seconds", r.seconds, 4);
    visit("cpu_seconds", r.cpu_seconds, 4);
    visit("sources_used", r.sources_used, 0);
    visit("coverage", r.coverage, 4);
    visit("mesh_pixels", r.mesh_pixels, 4);
    visit("infinity_pixels", r.infinity_pixels, 4);
    visit("filled_pixels", r.filled_pixels, 4);
    visit("filled_seen_pixels", r.filled_seen_pixels, 4);
    visit("width", r.width, 0);
    visit("height", r.height, 0);
  }
};

// An image name (which may hold '/', '\\' and spaces) as one file name: those become '_'.
std::string FlatImageName(const std::string& name);

// Thumbnails for the contact sheet (rendered beside the photo).
struct ViewThumbnails {
  std::string target;
  Image rendered, truth;
};

// LPIPS distance of (prediction, truth) in [0, 1] RGB; empty = not available.
using PerceptualDistance = std::function<double(const Image&, const Image&)>;

struct EvalRunOptions {
  RenderOptions render;  // K and model path are taken from the config
  PerceptualDistance lpips;
  int thumbnail_width = 0;       // > 0: collect thumbnails of this width
  std::string write_images_dir;  // non-empty: write <dir>/<slug>/<target>.png
  std::string scene_name;        // the "scene" column
  bool show_progress = true;
  // Not null: views it kept are not rendered again, and each view evaluated is recorded
  // in it as soon as it is done (eval/view_journal.h). Not owned.
  const ViewJournal* journal = nullptr;
};

// Loads every photo once (so that no view's time includes reading files) and returns the
// views whose photo cannot be used, with the reason, in *bad_photos (index -> error).
void PreloadPhotos(const Scene& scene,
                   std::vector<std::pair<int, std::string>>* bad_photos);

// Evaluates `targets` (already sharded) with one configuration. Never throws for a bad
// view; throws fvs::Error only when the method cannot be created at all.
std::vector<ViewResult> EvaluateTargets(
    const Scene& scene, const TargetSet& set, const std::vector<EvalTarget>& targets,
    const EvalConfig& config, const EvalRunOptions& options,
    const std::vector<std::pair<int, std::string>>& bad_photos,
    std::vector<ViewThumbnails>* thumbnails = nullptr);

}  // namespace fvs::eval
