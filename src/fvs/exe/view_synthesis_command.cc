// colmap view_synthesis --workspace_path W --output_path O
//   targets: --target_images images.txt | --camera_path camera_path.json | --orbit N |
//            --interpolate N
//   --method ulr|nearest|fvs, --num_sources K, --width/--height/--scale,
//   --write_depth, --write_confidence, --write_sources
// Renders every target into O/<name>.png (plus the optional extras, see render_output.h)
// and prints a per-target timing summary (depth / selection / warp / blend).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "fvs/exe/command_registry.h"
#include "fvs/exe/option_manager.h"
#include "fvs/render/method.h"
#include "fvs/render/render_output.h"
#include "fvs/render/targets.h"
#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

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
  RenderOptions render;
  RenderOutputOptions output;

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
  }
};

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
  options.AddDefault("num_sources", &o.render.num_sources, "K sources per target");
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
  options.AddDefault("write_sources", &o.output.write_sources,
                     "also write <name>.sources.json");
  options.AddDefault("num_threads", &o.render.num_threads, "threads (0: all cores)");
  if (!options.Parse(argc, argv)) return 0;
  o.Check();

  // Before the (slow) scene load: an unusable method fails at once.
  std::unique_ptr<Method> method = CreateMethod(o.method, o.render);
  Scene scene = Scene::Load(o.workspace_path, {true, o.render.num_threads});
  const std::vector<TargetCamera> targets = LoadTargets(o, scene);
  std::error_code ec;
  std::filesystem::create_directories(o.output_path, ec);
  Require(!ec, o.output_path, "cannot create the output folder: " + ec.message());

  std::vector<RenderTimings> timings;
  std::vector<double> coverage;
  Progress progress("view_synthesis " + o.method, static_cast<int64_t>(targets.size()));
  for (const TargetCamera& t : targets) {
    TargetView view;
    view.name = t.name;
    view.camera = scene.ToSceneCamera(ResizeTarget(t.camera, o.width, o.height, o.scale));
    Require(view.camera.IsValid(), t.name, "invalid target camera");
    if (o.holdout && !t.image_name.empty()) {
      const int index = scene.FindView(t.image_name);
      if (index >= 0) view.exclude_views.push_back(index);
    }
    const RenderResult result = method->Render(scene, view);
    WriteRenderOutputs(o.output_path, t.name, o.method, scene, result, o.output);
    timings.push_back(result.timings);
    double covered = 0;
    for (float c : result.coverage.data) covered += c;
    coverage.push_back(covered / std::max<size_t>(1, result.coverage.data.size()));
    progress.Advance();
  }
  progress.Finish();

  std::printf("scene: %d views, loaded in %.2f s (%d source depths computed)\n",
              scene.num_views(), scene.load_seconds(), scene.num_depths_computed());
  std::printf("%-24s %8s %8s %8s %8s %8s %8s %9s\n", "target", "total_s", "depth_s",
              "select_s", "warp_s", "encode_s", "blend_s", "coverage");
  RenderTimings sum;
  for (size_t i = 0; i < targets.size(); ++i) {
    const RenderTimings& t = timings[i];
    std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %8.1f%%\n",
                targets[i].name.c_str(), t.total(), t.depth_s, t.selection_s, t.warp_s,
                t.encode_s, t.blend_s, 100 * coverage[i]);
    sum.depth_s += t.depth_s;
    sum.selection_s += t.selection_s;
    sum.warp_s += t.warp_s;
    sum.encode_s += t.encode_s;
    sum.blend_s += t.blend_s;
  }
  const double n = static_cast<double>(targets.size());
  std::printf("%-24s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f\n", "mean", sum.total() / n,
              sum.depth_s / n, sum.selection_s / n, sum.warp_s / n, sum.encode_s / n,
              sum.blend_s / n);
  std::printf("wrote %zu images to %s\n", targets.size(), o.output_path.c_str());
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis", "render novel views (ulr, nearest, fvs)",
                     RunViewSynthesis);

}  // namespace fvs
