// colmap view_synthesis --workspace_path W --output_path O
//   targets: --target_images images.txt | --camera_path camera_path.json | --orbit N |
//            --interpolate N
//   --method ulr|nearest|fvs, --num_sources K, --width/--height/--scale,
//   --write_depth, --write_confidence, --write_infinity, --write_sources
//   videos: --video out.mp4 (ffmpeg when installed), --fps, --stable_sources 1
//   (--source_hysteresis, --stable_source_order), --temporal_blend a, --flag_coverage c,
//   --ground_truth_path G (PSNR of every frame that has an image of its name in G)
// Renders every target into O/<name>.png, resuming what an earlier run finished, and
// prints a per-target timing summary: RunRenderTargets (controllers/render_targets.h)
// does the work and states what is resumed and reported.
#include "fvs/controllers/render_targets.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/render_flags.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

// The workspace, the output folder and what the targets are.
void AddTargetFlags(OptionManager* options, RenderTargetsOptions* o) {
  options->AddRequired("workspace_path", &o->workspace_path, "prepared dense workspace");
  options->AddRequired("output_path", &o->output_path, "folder for the rendered images");
  options->AddDefault("target_images", &o->target_images,
                      "COLMAP images.txt of target poses (cameras.txt beside it, or the "
                      "workspace's camera ids)");
  options->AddDefault("camera_path", &o->camera_path, "nerfstudio camera_path.json");
  options->AddDefault("orbit", &o->orbit, "N views on a circle around the scene centre");
  options->AddDefault("interpolate", &o->interpolate,
                      "N views between consecutive registered cameras");
}

// The method and its sources, and the size of the frames.
void AddMethodFlags(OptionManager* options, RenderTargetsOptions* o) {
  options->AddDefault("method", &o->method, "ulr, nearest or fvs (needs --model_path)");
  options->AddDefault("model_path", &o->render.model_path,
                      "network weights (--method fvs)");
  options->AddDefault("num_sources", &o->render.num_sources,
                      "K sources per target; 0 = adaptive, up to --max_num_sources");
  options->AddDefault("width", &o->width, "output width (0: the target camera's)");
  options->AddDefault("height", &o->height, "output height (0: the target camera's)");
  options->AddDefault("scale", &o->scale, "scale of the output size");
  options->AddDefault("holdout", &o->holdout,
                      "a target named like a registered image does not use that image");
}

// What is written besides the colour.
void AddOutputFlags(OptionManager* options, RenderTargetsOptions* o) {
  options->AddDefault("write_depth", &o->output.write_depth,
                      "also write <name>.depth.bin and <name>.depth.png");
  options->AddDefault("write_confidence", &o->output.write_confidence,
                      "also write <name>.confidence.png");
  options->AddDefault("write_infinity", &o->output.write_infinity,
                      "also write <name>.infinity.png (white: rendered from the "
                      "background at infinity)");
  options->AddDefault("write_sources", &o->output.write_sources,
                      "also write <name>.sources.json");
}

// The network methods' precision and disk cache (the rest of the engine's flags are
// AddRenderEngineFlags).
void AddNetworkFlags(OptionManager* options, RenderTargetsOptions* o) {
  options->AddDefault("precision", &o->render.precision,
                      "--method fvs: fp32, bf16, or fp16 (CUDA only)");
  options->AddDefault("disk_feature_cache", &o->disk_feature_cache,
                      "--method fvs: also keep encoded source features in "
                      "W/fvs/features/, read by later runs instead of encoding (about "
                      "80 MB per 640x480 source)");
  options->AddDefault(
      "feature_cache_disk_mb", &o->render.feature_cache_disk_mb,
      "--disk_feature_cache: size limit of W/fvs/features (least recently "
      "used out first)");
}

// Videos: encoding, resuming, temporal stability, reports, shards.
void AddSequenceFlags(OptionManager* options, RenderTargetsOptions* o) {
  options->AddDefault(
      "video", &o->video,
      "also encode the frames into this H.264 mp4 (needs ffmpeg on the PATH "
      "or FVS_FFMPEG; without it only the frames are written)");
  options->AddDefault("fps", &o->fps, "video frame rate (0: the camera path's, else 30)");
  options->AddDefault(
      "overwrite", &o->overwrite,
      "render every target again (default: skip targets whose PNG exists)");
  options->AddDefault("stable_sources", &o->stable_sources,
                      "temporally stable sources: --source_hysteresis 0.1 (unless given) "
                      "and --stable_source_order 1");
  options->AddDefault("source_hysteresis", &o->render.source_hysteresis,
                      "keep the previous frame's sources unless another sees this much "
                      "more (0.1 = 10%); 0: off");
  options->AddDefault("stable_source_order", &o->render.stable_source_order,
                      "blend the sources in view order, not best first");
  options->AddDefault("temporal_blend", &o->temporal.temporal_blend,
                      "share of the previous output, warped into the frame, where the "
                      "geometry agrees (0: off)");
  options->AddDefault("flag_coverage", &o->temporal.coverage_threshold,
                      "frames with less coverage are flagged in frame_report.csv");
  options->AddDefault("ground_truth_path", &o->ground_truth_path,
                      "folder of ground-truth frames named as the output "
                      "(<name>.png/.jpg): PSNR per frame in frame_report.csv");
  options->AddDefault(
      "shard", &o->shard,
      "i/n: render only targets i, i+n, i+2n, ... (Slurm/Kubernetes array "
      "jobs; file names stay those of the full path)");
}

int RunViewSynthesis(int argc, char** argv) {
  RenderTargetsOptions o;
  OptionManager options(
      "view_synthesis",
      "Render novel views of a prepared workspace (view_synthesis_prepare).");
  AddTargetFlags(&options, &o);
  AddMethodFlags(&options, &o);
  AddRenderEngineFlags(&options, &o.render);
  AddOutputFlags(&options, &o);
  AddNetworkFlags(&options, &o);
  AddSequenceFlags(&options, &o);
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(o.output_path, "view_synthesis", o.shard);
  PrintRenderTargetsSummary(o, RunRenderTargets(o));
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis", "render novel views (ulr, nearest, fvs)",
                     RunViewSynthesis);

}  // namespace fvs
