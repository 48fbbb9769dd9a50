// colmap view_synthesis --workspace_path W --output_path O
//   targets: --target_images images.txt | --camera_path camera_path.json | --orbit N |
//            --interpolate N
//   --method ulr|nearest|fvs, --num_sources K, --width/--height/--scale,
//   --write_depth, --write_confidence, --write_infinity, --write_sources
//   videos: --video out.mp4 (ffmpeg when installed), --fps, --stable_sources 1
//   (--source_hysteresis, --stable_source_order), --temporal_blend a, --flag_coverage c,
//   --ground_truth_path G (PSNR of every frame that has an image of its name in G)
// Renders every target into O/<name>.png (plus the optional extras, see render_output.h)
// and prints a per-target timing summary (depth / selection / warp / blend). A target
// whose PNG already exists (and has the right size) is skipped unless --overwrite 1, so
// an interrupted render resumes at the first missing frame. Frames are resumed only when
// O/render_settings.json matches this run: the settings, and the content hashes of the
// weights, of the workspace (sparse model, mesh, photos) and of the target file, so
// weights retrained to the same path never reuse old frames. O/frame_report.{csv,json}
// hold per frame the coverage (flagged under --flag_coverage), the sources, the flicker
// to the previous frame (fvs/path/flicker.h) and the PSNR against the ground truth. The
// temporal chain (stable sources, blend, flicker) goes on across resumed frames: the last
// frame on disk before a missing one is rendered again, its colour taken from disk.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "colmap_ext/image_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/eval/metrics.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/option_manager.h"
#include "fvs/path/frame_report.h"
#include "fvs/path/temporal.h"
#include "fvs/path/video.h"
#include "fvs/render/method.h"
#include "fvs/render/render_output.h"
#include "fvs/render/targets.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/hash.h"
#include "fvs/util/machine.h"
#include "fvs/util/progress.h"
#include "fvs/util/shard.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

struct ViewSynthesisOptions {
  std::string workspace_path;
  std::string output_path;
  std::string target_images;
  std::string camera_path;
  int orbit = 0;
  int interpolate = 0;
  std::string method = "ulr";
  int width = 0;
  int height = 0;
  double scale = 1.0;
  bool holdout = false;
  bool disk_feature_cache = false;  // encoded features under W/fvs/features
  std::string shard;                // "i/n": every n-th target from i (batch array jobs)
  RenderOptions render;
  RenderOutputOptions output;
  // Videos.
  std::string video;
  double fps = 0;  // 0: the camera path's "fps", else 30
  bool overwrite = false;
  bool stable_sources = false;
  TemporalOptions temporal;
  std::string ground_truth_path;

  void Check() const {
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
};

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

// The regular files below `folder` (or `folder` itself when a file), sorted; none when
// it does not exist.
std::vector<std::string> FilesBelow(const std::string& folder) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  std::error_code ec;
  if (fs::is_regular_file(folder, ec)) return {folder};
  for (auto it = fs::recursive_directory_iterator(folder, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->is_regular_file()) files.push_back(it->path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Content hash of `paths` (files, or folders: every file below them), names relative to
// `root` included: the same bytes wherever they lie give the same hash.
std::string ContentHash(const std::vector<std::string>& paths, const std::string& root) {
  uint64_t hash = 0;
  for (const std::string& path : paths) {
    for (const std::string& file : FilesBelow(path)) {
      const std::string name = std::filesystem::path(file).lexically_relative(root);
      hash = HashFile(file, Hash64(name.data(), name.size(), hash));
    }
  }
  return HexHash(hash);
}

// What the renderer takes from the workspace: the sparse model, the mesh and the
// undistorted photos (the source depths follow from the first two).
std::string WorkspaceHash(const std::string& workspace_path) {
  const colmap::DenseWorkspace ws(workspace_path);
  return ContentHash({ws.SparseDir(), ws.DelaunayMeshPath(), ws.ImagesDir()},
                     workspace_path);
}

// The target file and, for images.txt, the cameras.txt beside it.
std::string TargetsHash(const ViewSynthesisOptions& o) {
  if (!o.camera_path.empty()) {
    return ContentHash({o.camera_path},
                       std::filesystem::path(o.camera_path).parent_path().string());
  }
  if (o.target_images.empty()) return "";
  const std::filesystem::path folder =
      std::filesystem::path(o.target_images).parent_path();
  return ContentHash({o.target_images, (folder / "cameras.txt").string()},
                     folder.string());
}

// What decides the pixels of a frame: a frame rendered with other settings, weights,
// workspace or targets (compared by content, not by path or time) is not resumed.
std::string RenderSettings(const ViewSynthesisOptions& o) {
  nlohmann::json json;
  json["method"] = o.method;
  if (!o.render.model_path.empty()) {
    json["weights_hash"] = HexHash(HashFile(o.render.model_path));
  }
  json["workspace_hash"] = WorkspaceHash(o.workspace_path);
  json["num_sources"] = o.render.num_sources;
  if (o.render.num_sources == 0) json["max_num_sources"] = o.render.max_num_sources;
  json["selection_tolerance"] = o.render.selection_tolerance;
  json["warp_tolerance"] = o.render.warp_tolerance;
  json["width"] = o.width;
  json["height"] = o.height;
  json["scale"] = o.scale;
  json["holdout"] = o.holdout;
  json["source_hysteresis"] = o.render.source_hysteresis;
  json["stable_source_order"] = o.render.stable_source_order;
  json["temporal_blend"] = o.temporal.temporal_blend;
  json["fill_holes"] = o.render.fill_holes;
  // Tiles change the network's context at their seams.
  if (o.method != "ulr" && o.method != "nearest") {
    json["precision"] = o.render.precision;
    json["tile_size"] = o.render.tile_size;
    json["tile_overlap"] = o.render.tile_overlap;
  }
  json["targets"] = !o.target_images.empty() ? "target_images"
                    : !o.camera_path.empty() ? "camera_path"
                    : o.orbit > 0            ? "orbit " + std::to_string(o.orbit)
                                  : "interpolate " + std::to_string(o.interpolate);
  const std::string targets_hash = TargetsHash(o);
  if (!targets_hash.empty()) json["targets_hash"] = targets_hash;
  return json.dump(2) + "\n";
}

// The ground-truth image of a frame: <dir>/<name>.png, .jpg or .JPG (empty: none).
std::string GroundTruthFile(const std::string& dir, const std::string& name) {
  if (dir.empty()) return "";
  for (const char* ext : {".png", ".jpg", ".JPG", ".jpeg"}) {
    const std::string path = JoinPaths(dir, name + ext);
    if (std::filesystem::exists(path)) return path;
  }
  return "";
}

// A ground truth of another size than its frame is an error (it is not the frame it
// claims to be).
void RequireGroundTruthSize(const std::string& path, int truth_width, int truth_height,
                            int width, int height) {
  Require(truth_width == width && truth_height == height, path,
          "ground truth of " + std::to_string(truth_width) + "x" +
              std::to_string(truth_height) + " for a frame of " + std::to_string(width) +
              "x" + std::to_string(height));
}

// Checks, from the headers, the ground truth of a frame of this size, if there is one:
// run on every target before the first frame, so that a bad one writes nothing.
void CheckGroundTruth(const std::string& dir, const std::string& name,
                      const PinholeCamera& camera) {
  const std::string path = GroundTruthFile(dir, name);
  if (path.empty()) return;
  int width = 0, height = 0;
  colmap::ReadImageSize(path, &width, &height);
  RequireGroundTruthSize(path, width, height, camera.width, camera.height);
}

// PSNR of a rendered frame against its ground truth; -1 without one.
double FramePsnr(const std::string& dir, const std::string& name, const Image& color) {
  const std::string path = GroundTruthFile(dir, name);
  if (path.empty()) return -1;
  const Image truth = colmap::ReadImage(path);
  RequireGroundTruthSize(path, truth.width, truth.height, color.width, color.height);
  return eval::Psnr(color, truth);
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

std::vector<int> ParseSources(const std::string& text) {
  std::vector<int> out;
  for (const std::string& s : SplitString(text, ";")) {
    try {
      if (!s.empty()) out.push_back(std::stoi(s));
    } catch (const std::exception&) {
    }
  }
  return out;
}

std::vector<TargetCamera> LoadTargets(const ViewSynthesisOptions& o, const Scene& scene) {
  if (!o.target_images.empty()) return ReadTargetImagesTxt(o.target_images, scene);
  if (!o.camera_path.empty()) return ReadNerfstudioCameraPath(o.camera_path);
  if (o.orbit > 0) return OrbitTargets(scene, o.orbit);
  return InterpolateTargets(scene, o.interpolate);
}

int RunViewSynthesis(int argc, char** argv) {
  ViewSynthesisOptions o;
  OptionManager options(
      "view_synthesis",
      "Render novel views of a prepared workspace (view_synthesis_prepare).");
  options.AddRequired("workspace_path", &o.workspace_path, "prepared dense workspace");
  options.AddRequired("output_path", &o.output_path, "folder for the rendered images");
  options.AddDefault("target_images", &o.target_images,
                     "COLMAP images.txt of target poses (cameras.txt beside it, or the "
                     "workspace's camera ids)");
  options.AddDefault("camera_path", &o.camera_path, "nerfstudio camera_path.json");
  options.AddDefault("orbit", &o.orbit, "N views on a circle around the scene centre");
  options.AddDefault("interpolate", &o.interpolate,
                     "N views between consecutive registered cameras");
  options.AddDefault("method", &o.method, "ulr, nearest or fvs (needs --model_path)");
  options.AddDefault("model_path", &o.render.model_path,
                     "network weights (--method fvs)");
  options.AddDefault("num_sources", &o.render.num_sources,
                     "K sources per target; 0 = adaptive, up to --max_num_sources");
  options.AddDefault("max_num_sources", &o.render.max_num_sources,
                     "the most sources an adaptive K (0) takes");
  options.AddDefault("selection_tolerance", &o.render.selection_tolerance,
                     "relative depth tolerance for ranking sources");
  options.AddDefault("warp_tolerance", &o.render.warp_tolerance,
                     "relative occlusion tolerance when warping");
  options.AddDefault("width", &o.width, "output width (0: the target camera's)");
  options.AddDefault("height", &o.height, "output height (0: the target camera's)");
  options.AddDefault("scale", &o.scale, "scale of the output size");
  options.AddDefault("holdout", &o.holdout,
                     "a target named like a registered image does not use that image");
  options.AddDefault("write_depth", &o.output.write_depth,
                     "also write <name>.depth.bin and <name>.depth.png");
  options.AddDefault("write_confidence", &o.output.write_confidence,
                     "also write <name>.confidence.png");
  options.AddDefault("write_infinity", &o.output.write_infinity,
                     "also write <name>.infinity.png (white: rendered from the "
                     "background at infinity)");
  options.AddDefault("write_sources", &o.output.write_sources,
                     "also write <name>.sources.json");
  options.AddDefault("fill_holes", &o.render.fill_holes,
                     "fill pixels no source sees from the covered pixels around them "
                     "(0: leave them black; frame_report.csv counts them either way)");
  options.AddDefault("device", &o.render.device,
                     "--method fvs: auto (CUDA when there is one), cpu or cuda");
  options.AddDefault("precision", &o.render.precision,
                     "--method fvs: fp32, bf16, or fp16 (CUDA only)");
  options.AddDefault("feature_cache_mb", &o.render.feature_cache_mb,
                     "--method fvs: memory for encoded source features kept across "
                     "targets (0: none)");
  options.AddDefault("disk_feature_cache", &o.disk_feature_cache,
                     "--method fvs: also keep encoded source features in "
                     "W/fvs/features/, read by later runs instead of encoding (about "
                     "80 MB per 640x480 source)");
  options.AddDefault("feature_cache_disk_mb", &o.render.feature_cache_disk_mb,
                     "--disk_feature_cache: size limit of W/fvs/features (least recently "
                     "used out first)");
  options.AddDefault("tile_size", &o.render.tile_size,
                     "--method fvs: blend targets larger than this in tiles of at most "
                     "this size, to bound memory and stay in cache (0: never; -1: the "
                     "network's own, 160 for fvs_agg, 512 for the others)");
  options.AddDefault("tile_overlap", &o.render.tile_overlap,
                     "--method fvs: pixels of context around each tile (-1: the "
                     "network's own, 24 for fvs_agg, 32 for the others)");
  options.AddDefault("num_threads", &o.render.num_threads, "threads (0: all cores)");
  options.AddDefault(
      "video", &o.video,
      "also encode the frames into this H.264 mp4 (needs ffmpeg on the PATH "
      "or FVS_FFMPEG; without it only the frames are written)");
  options.AddDefault("fps", &o.fps, "video frame rate (0: the camera path's, else 30)");
  options.AddDefault(
      "overwrite", &o.overwrite,
      "render every target again (default: skip targets whose PNG exists)");
  options.AddDefault("stable_sources", &o.stable_sources,
                     "temporally stable sources: --source_hysteresis 0.1 (unless given) "
                     "and --stable_source_order 1");
  options.AddDefault("source_hysteresis", &o.render.source_hysteresis,
                     "keep the previous frame's sources unless another sees this much "
                     "more (0.1 = 10%); 0: off");
  options.AddDefault("stable_source_order", &o.render.stable_source_order,
                     "blend the sources in view order, not best first");
  options.AddDefault("temporal_blend", &o.temporal.temporal_blend,
                     "share of the previous output, warped into the frame, where the "
                     "geometry agrees (0: off)");
  options.AddDefault("flag_coverage", &o.temporal.coverage_threshold,
                     "frames with less coverage are flagged in frame_report.csv");
  options.AddDefault("ground_truth_path", &o.ground_truth_path,
                     "folder of ground-truth frames named as the output "
                     "(<name>.png/.jpg): PSNR per frame in frame_report.csv");
  options.AddDefault("shard", &o.shard,
                     "i/n: render only targets i, i+n, i+2n, ... (Slurm/Kubernetes array "
                     "jobs; file names stay those of the full path)");
  if (!options.Parse(argc, argv)) return 0;
  o.render.scene_model_dir = WorkspaceFinetunedModelDir(o.workspace_path);
  if (o.disk_feature_cache) {
    o.render.feature_cache_dir = WorkspaceFeatureCacheDir(o.workspace_path);
  }
  if (o.stable_sources) {
    if (o.render.source_hysteresis == 0) o.render.source_hysteresis = 0.1;
    o.render.stable_source_order = true;
  }
  o.Check();
  if (o.fps == 0) {
    o.fps = o.camera_path.empty() ? 0.0 : CameraPathFps(o.camera_path);
    if (o.fps == 0) o.fps = 30;
  }

  // Before the (slow) scene load: an unusable method fails at once.
  std::unique_ptr<Method> method = CreateMethod(o.method, o.render);
  Scene scene = Scene::Load(o.workspace_path, {true, o.render.num_threads});
  std::vector<TargetCamera> targets = LoadTargets(o, scene);
  if (const Shard shard = Shard::Parse(o.shard); !shard.IsAll()) {
    std::vector<TargetCamera> mine;
    for (int i : shard.Items(static_cast<int>(targets.size())))
      mine.push_back(targets[i]);
    if (mine.empty()) {
      std::printf("shard %s: no targets (the path has %zu)\n", o.shard.c_str(),
                  targets.size());
      return 0;
    }
    targets = std::move(mine);
  }
  // Photos are read and ground truth compared frame by frame: check them (headers only)
  // before the output folder is touched, so that bad input leaves nothing behind.
  CheckSourcePhotos(scene);
  for (const TargetCamera& t : targets) {
    CheckGroundTruth(o.ground_truth_path, t.name,
                     ResizeTarget(t.camera, o.width, o.height, o.scale));
  }
  std::error_code ec;
  std::filesystem::create_directories(o.output_path, ec);
  Require(!ec, o.output_path, "cannot create the output folder: " + ec.message());

  // Resume: the frames already on disk are skipped (their report rows are kept), when
  // they were rendered with the same settings (recorded before the first frame, so a
  // killed run has them too).
  const std::string settings = RenderSettings(o);
  const std::string settings_path = JoinPaths(o.output_path, "render_settings.json");
  bool overwrite = o.overwrite;
  if (!overwrite) {
    std::string previous;
    try {
      previous = ReadFileToString(settings_path);
    } catch (const Error&) {
    }
    if (previous != settings) {
      overwrite = true;
      if (!previous.empty()) {
        std::printf(
            "the render settings differ from those of the frames in %s: "
            "rendering every target again\n",
            o.output_path.c_str());
      }
    }
  }
  WriteFileAtomic(settings_path, [&](std::ostream& out) { out << settings; });
  std::vector<PinholeCamera> cameras;
  int64_t to_render = 0;
  std::vector<bool> done;
  for (const TargetCamera& t : targets) {
    cameras.push_back(ResizeTarget(t.camera, o.width, o.height, o.scale));
    done.push_back(!overwrite &&
                   colmap::IsCompleteImage(JoinPaths(o.output_path, t.name + ".png"),
                                           cameras.back().width, cameras.back().height));
    to_render += !done.back();
  }
  if (to_render < static_cast<int64_t>(targets.size())) {
    std::printf(
        "resuming: %zu of %zu frames already rendered (--overwrite 1 redoes them)\n",
        targets.size() - to_render, targets.size());
  }
  // Shards of one render write their own reports.
  std::string report_stem = JoinPaths(o.output_path, "frame_report");
  if (!o.shard.empty() && !Shard::Parse(o.shard).IsAll()) {
    std::string tag = o.shard;
    std::replace(tag.begin(), tag.end(), '/', '_');
    report_stem += ".shard_" + tag;
  }
  const std::map<std::string, FrameReportRow> earlier =
      overwrite ? std::map<std::string, FrameReportRow>()
                : ReadFrameReport(report_stem + ".csv");
  nlohmann::json report_extra = nlohmann::json::parse(settings);
  if (!o.render.model_path.empty()) report_extra["model_path"] = o.render.model_path;
  report_extra["machine"] = DescribeMachine();
  TemporalSequence sequence(o.temporal);
  std::vector<FrameReportRow> report;
  std::vector<RenderTimings> timings;
  std::vector<double> coverage;
  std::vector<size_t> rendered;  // indices into targets
  auto make_view = [&](size_t k) {
    const TargetCamera& t = targets[k];
    TargetView view;
    view.name = t.name;
    view.camera = scene.ToSceneCamera(cameras[k]);
    Require(view.camera.IsValid(), t.name, "invalid target camera");
    if (o.holdout && !t.image_name.empty()) {
      const int index = scene.FindView(t.image_name);
      if (index >= 0) view.exclude_views.push_back(index);
    }
    return view;
  };
  // The frame before a missing one was resumed from disk: render it again (with the
  // sources its report row names preferred) and continue the chain from its colour on
  // disk, so that resuming does not restart the stable sources, blend and flicker.
  auto restore_chain = [&](size_t k) {
    TargetView view = make_view(k);
    const auto it = earlier.find(targets[k].name);
    if (it != earlier.end()) view.preferred_sources = ParseSources(it->second.sources);
    RenderResult result = method->Render(scene, view);
    try {
      result.color =
          colmap::ReadImage(JoinPaths(o.output_path, targets[k].name + ".png"));
    } catch (const Error&) {
      return;  // unreadable after all: the chain restarts
    }
    sequence.Remember(view, result);
  };
  Progress progress("view_synthesis " + o.method, to_render);
  for (size_t k = 0; k < targets.size(); ++k) {
    const TargetCamera& t = targets[k];
    if (done[k]) {
      sequence.Reset();
      const auto it = earlier.find(t.name);
      FrameReportRow row = it != earlier.end() ? it->second : FrameReportRow();
      row.frame = t.name;
      row.status = "resumed";
      report.push_back(row);
      continue;
    }
    if (k > 0 && done[k - 1]) restore_chain(k - 1);
    TargetView view = make_view(k);
    sequence.PrepareView(&view);
    Timer frame_timer;
    RenderResult result = method->Render(scene, view);
    FrameReportRow row = sequence.Finish(view, &result);
    WriteRenderOutputs(o.output_path, t.name, o.method, scene, result, o.output);
    row.seconds = frame_timer.Seconds();
    row.psnr = FramePsnr(o.ground_truth_path, t.name, result.color);
    report.push_back(row);
    timings.push_back(result.timings);
    coverage.push_back(row.coverage);
    rendered.push_back(k);
    // Every frame, so that a killed run keeps the rows of what it finished.
    WriteFrameReport(report_stem, report,
                     SummariseFrameReport(report, o.temporal.coverage_threshold),
                     report_extra.dump());
    progress.Advance();
  }
  progress.Finish();
  const FrameReportSummary summary =
      SummariseFrameReport(report, o.temporal.coverage_threshold);
  WriteFrameReport(report_stem, report, summary, report_extra.dump());

  std::printf("scene: %d views, loaded in %.2f s (%d source depths computed)\n",
              scene.num_views(), scene.load_seconds(), scene.num_depths_computed());
  std::printf("%-24s %8s %8s %8s %8s %8s %8s %9s\n", "target", "total_s", "depth_s",
              "select_s", "warp_s", "encode_s", "blend_s", "coverage");
  RenderTimings sum;
  for (size_t i = 0; i < rendered.size(); ++i) {
    const RenderTimings& t = timings[i];
    std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1f%%\n",
                targets[rendered[i]].name.c_str(), t.total(), t.depth_s, t.selection_s,
                t.warp_s, t.encode_s, t.blend_s, 100 * coverage[i]);
    sum.depth_s += t.depth_s;
    sum.selection_s += t.selection_s;
    sum.warp_s += t.warp_s;
    sum.encode_s += t.encode_s;
    sum.blend_s += t.blend_s;
  }
  const double n = static_cast<double>(std::max<size_t>(1, rendered.size()));
  std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f\n", "mean", sum.total() / n,
              sum.depth_s / n, sum.selection_s / n, sum.warp_s / n, sum.encode_s / n,
              sum.blend_s / n);
  std::printf("wrote %zu images to %s (%zu resumed)\n", rendered.size(),
              o.output_path.c_str(), targets.size() - rendered.size());
  std::printf("frames: %d, mean coverage %.1f%%, %zu flagged under %.0f%%%s\n",
              summary.num_frames, 100 * summary.mean_coverage, summary.flagged.size(),
              100 * o.temporal.coverage_threshold,
              summary.flagged.empty() ? "" : " (see frame_report.csv)");
  if (summary.mean_flicker >= 0) {
    std::printf(
        "flicker: %.3f levels (mean |frame t+1 - warped frame t|, 8-bit), %.2f "
        "source changes per frame, %.1f ms per frame (%.1f ms of it temporal "
        "blend + flicker)\n",
        summary.mean_flicker, summary.mean_source_changes, 1000 * summary.mean_seconds,
        1000 * summary.mean_temporal_seconds);
  }
  if (summary.num_psnr > 0) {
    std::printf("ground truth: PSNR %.2f dB over %d of %d frames (%s)\n",
                summary.mean_psnr, summary.num_psnr, summary.num_frames,
                o.ground_truth_path.c_str());
  } else if (!o.ground_truth_path.empty()) {
    std::printf("ground truth: no frame has an image in %s\n",
                o.ground_truth_path.c_str());
  }
  if (!o.video.empty()) {
    std::vector<std::string> frames;
    for (const TargetCamera& t : targets) {
      frames.push_back(JoinPaths(o.output_path, t.name + ".png"));
    }
    const VideoResult video = EncodeVideo(frames, o.fps, o.video);
    std::printf("%s%s\n", video.written ? "" : "NOTE: ", video.note.c_str());
  }
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis", "render novel views (ulr, nearest, fvs)",
                     RunViewSynthesis);

}  // namespace fvs
