#include "fvs/controllers/render_targets.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "colmap_ext/image_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/controllers/ground_truth.h"
#include "fvs/controllers/render_settings.h"
#include "fvs/render/targets.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/progress.h"
#include "fvs/util/shard.h"
#include "fvs/util/stale_temp_files.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

double CameraPathFps(const std::string& path) {
  try {
    std::ifstream in(path);
    const nlohmann::json json = nlohmann::json::parse(in);
    const double fps = json.value("fps", 0.0);
    return std::isfinite(fps) && fps > 0 ? fps : 0.0;
  } catch (const std::exception&) {
    return 0.0;
  }
}

// The settings the options imply: the workspace's folders, what --stable_sources stands
// for and the frame rate.
void CompleteOptions(RenderTargetsOptions* o) {
  o->render.scene_model_dir = WorkspaceFinetunedModelDir(o->workspace_path);
  if (o->disk_feature_cache) {
    o->render.feature_cache_dir = WorkspaceFeatureCacheDir(o->workspace_path);
  }
  if (o->stable_sources) {
    if (o->render.source_hysteresis == 0) o->render.source_hysteresis = 0.1;
    o->render.stable_source_order = true;
  }
  o->Check();
  if (o->fps == 0) {
    o->fps = o->camera_path.empty() ? 0.0 : CameraPathFps(o->camera_path);
    if (o->fps == 0) o->fps = 30;
  }
}

std::vector<TargetCamera> LoadTargets(const RenderTargetsOptions& o, const Scene& scene) {
  if (!o.target_images.empty()) return ReadTargetImagesTxt(o.target_images, scene);
  if (!o.camera_path.empty()) return ReadNerfstudioCameraPath(o.camera_path);
  if (o.orbit > 0) return OrbitTargets(scene, o.orbit);
  return InterpolateTargets(scene, o.interpolate);
}

std::vector<TargetCamera> TargetsOfShard(std::vector<TargetCamera> targets,
                                         const Shard& shard) {
  if (shard.IsAll()) return targets;
  std::vector<TargetCamera> mine;
  for (int i : shard.Items(static_cast<int>(targets.size()))) mine.push_back(targets[i]);
  return mine;
}

// Checks, from their headers only, that every view's photo exists, decodes as an image
// and has its camera's size. The renderer reads photos lazily, when a frame first uses
// them: checked up front, a broken photo fails before the output folder is touched.
void CheckSourcePhotos(const Scene& scene) {
  const colmap::DenseWorkspace workspace(scene.workspace_path());
  for (const SceneView& view : scene.views()) {
    const std::string path = workspace.ImagePath(view.name);
    int width = 0, height = 0;
    colmap::ReadImageSize(path, &width, &height);
    Require(width == view.camera.width && height == view.camera.height, path,
            "image is " + std::to_string(width) + "x" + std::to_string(height) +
                " but its camera is " + std::to_string(view.camera.width) + "x" +
                std::to_string(view.camera.height) +
                " (not an undistorted dense workspace?)");
  }
}

// Whether frames on disk may be kept: --overwrite not given and they were rendered with
// the same settings. Records this run's settings before the first frame, so that a
// killed run has them too.
bool ResumeAllowed(const RenderTargetsOptions& o, const std::string& settings) {
  // A killed run's half-written files go first: they are never frames.
  RemoveStaleTempFiles(o.output_path);
  const std::string settings_path = JoinPaths(o.output_path, "render_settings.json");
  bool resume = !o.overwrite;
  if (resume) {
    std::string previous;
    try {
      previous = ReadFileToString(settings_path);
    } catch (const Error&) {
    }
    if (previous != settings) {
      resume = false;
      if (!previous.empty()) {
        std::printf(
            "the render settings differ from those of the frames in %s: "
            "rendering every target again\n",
            o.output_path.c_str());
      }
    }
  }
  WriteFileAtomic(settings_path, [&](std::ostream& out) { out << settings; });
  return resume;
}

std::vector<RenderFrame> MakeFrames(const RenderTargetsOptions& o,
                                    const std::vector<TargetCamera>& targets,
                                    bool resume) {
  std::vector<RenderFrame> frames;
  for (const TargetCamera& t : targets) {
    RenderFrame frame;
    frame.target = t;
    frame.target.camera = ResizeTarget(t.camera, o.width, o.height, o.scale);
    frame.done = resume && colmap::IsCompleteImage(
                               JoinPaths(o.output_path, t.name + ".png"),
                               frame.target.camera.width, frame.target.camera.height);
    frames.push_back(frame);
  }
  return frames;
}

// Shards of one render write their own reports.
std::string ReportStem(const RenderTargetsOptions& o) {
  std::string stem = JoinPaths(o.output_path, "frame_report");
  if (!o.shard.empty() && !Shard::Parse(o.shard).IsAll()) {
    std::string tag = o.shard;
    std::replace(tag.begin(), tag.end(), '/', '_');
    stem += ".shard_" + tag;
  }
  return stem;
}

RenderFramesOptions FrameOptions(const RenderTargetsOptions& o,
                                 const std::string& settings, bool resume) {
  RenderFramesOptions frames;
  frames.output_path = o.output_path;
  frames.method = o.method;
  frames.output = o.output;
  frames.temporal = o.temporal;
  frames.holdout = o.holdout;
  frames.ground_truth_path = o.ground_truth_path;
  frames.report_stem = ReportStem(o);
  if (resume) frames.earlier = ReadFrameReport(frames.report_stem + ".csv");
  nlohmann::json extra = nlohmann::json::parse(settings);
  if (!o.render.model_path.empty()) extra["model_path"] = o.render.model_path;
  extra["machine"] = DescribeMachine();
  frames.report_extra_json = extra.dump();
  return frames;
}

// Renders what is missing of `targets` (checked) with a progress bar.
RenderFramesResult RenderMissingFrames(const RenderTargetsOptions& o, const Scene& scene,
                                       Method* method,
                                       const std::vector<TargetCamera>& targets) {
  std::error_code ec;
  std::filesystem::create_directories(o.output_path, ec);
  Require(!ec, o.output_path, "cannot create the output folder: " + ec.message());
  const std::string settings = RenderSettingsJson(o);
  const bool resume = ResumeAllowed(o, settings);
  const std::vector<RenderFrame> frames = MakeFrames(o, targets, resume);
  const int64_t to_render = std::count_if(frames.begin(), frames.end(),
                                          [](const RenderFrame& f) { return !f.done; });
  if (to_render < static_cast<int64_t>(frames.size())) {
    std::printf(
        "resuming: %zu of %zu frames already rendered (--overwrite 1 redoes them)\n",
        frames.size() - to_render, frames.size());
  }
  Progress progress("view_synthesis " + o.method, to_render);
  RenderFramesCallbacks callbacks;
  callbacks.after_frame = [&](size_t) { progress.Advance(); };
  RenderFramesResult result =
      RenderFrames(scene, method, frames, FrameOptions(o, settings, resume), callbacks);
  progress.Finish();
  return result;
}

}  // namespace

void RenderTargetsOptions::Check() const {
  const int given =
      !target_images.empty() + !camera_path.empty() + (orbit != 0) + (interpolate != 0);
  Require(
      given == 1, "colmap view_synthesis",
      "give exactly one of --target_images, --camera_path, --orbit N, --interpolate N");
  Require(orbit >= 0 && interpolate >= 0, "colmap view_synthesis",
          "--orbit and --interpolate need a positive count");
  Require(width >= 0 && height >= 0, "colmap view_synthesis",
          "--width and --height must not be negative");
  render.Check();
  temporal.Check();
  Require(std::isfinite(fps) && fps >= 0, "--fps", "must not be negative");
  Shard::Parse(shard);
}

RenderTargetsResult RunRenderTargets(RenderTargetsOptions o) {
  CompleteOptions(&o);
  // Before the (slow) scene load: an unusable method fails at once.
  std::unique_ptr<Method> method = CreateMethod(o.method, o.render);
  const Scene scene = Scene::Load(o.workspace_path, {true, o.render.num_threads});
  const std::vector<TargetCamera> all_targets = LoadTargets(o, scene);
  const std::vector<TargetCamera> targets =
      TargetsOfShard(all_targets, Shard::Parse(o.shard));
  RenderTargetsResult result;
  result.num_views = scene.num_views();
  if (targets.empty() && !Shard::Parse(o.shard).IsAll()) {
    std::printf("shard %s: no targets (the path has %zu)\n", o.shard.c_str(),
                all_targets.size());
    result.shard_empty = true;
    return result;
  }
  // Photos are read and ground truth compared frame by frame: check them (headers only)
  // before the output folder is touched, so that bad input leaves nothing behind.
  CheckSourcePhotos(scene);
  for (const TargetCamera& t : targets) {
    CheckGroundTruth(o.ground_truth_path, t.name,
                     ResizeTarget(t.camera, o.width, o.height, o.scale));
  }
  result.frames = RenderMissingFrames(o, scene, method.get(), targets);
  result.scene_load_seconds = scene.load_seconds();
  result.num_depths_computed = scene.num_depths_computed();
  for (const TargetCamera& t : targets) result.target_names.push_back(t.name);
  if (!o.video.empty()) {
    std::vector<std::string> frame_paths;
    for (const TargetCamera& t : targets) {
      frame_paths.push_back(JoinPaths(o.output_path, t.name + ".png"));
    }
    result.has_video = true;
    result.video = EncodeVideo(frame_paths, o.fps, o.video);
  }
  return result;
}

}  // namespace fvs
