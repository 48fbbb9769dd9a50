// colmap view_synthesis_synthetic --output_path DIR: generates the synthetic demo scene
// (a textured room with objects seen along a handheld-like path) as a COLMAP dense
// workspace with exact ground truth (see src/fvs/synthetic/generate.h for the layout).
#include <iostream>
#include <string>

#include "fvs/exe/command_registry.h"
#include "fvs/render/targets.h"
#include "fvs/synthetic/generate.h"
#include "fvs/util/error.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"
#include "fvs/util/progress.h"

namespace fvs {
namespace {

int RunViewSynthesisSynthetic(int argc, char** argv) {
  std::string output_path;
  std::string camera_path;
  SyntheticSceneOptions scene;
  int seed = 0;
  OptionManager options(
      "view_synthesis_synthetic",
      "Generates a synthetic textured scene with exact ground truth (images, "
      "sparse model, depth and normal maps, mesh) as a COLMAP workspace.");
  options.AddRequired("output_path", &output_path, "folder to write the scene to");
  options.AddDefault("camera_path", &camera_path,
                     "nerfstudio camera_path.json in the scene's frame: write only the "
                     "ground truth of its frames (<frame>.png), e.g. of a video "
                     "rendered from the generated workspace");
  options.AddDefault("SyntheticScene.num_views", &scene.num_views, "number of views");
  options.AddDefault("SyntheticScene.width", &scene.width, "image width in pixels");
  options.AddDefault("SyntheticScene.height", &scene.height, "image height in pixels");
  options.AddDefault("SyntheticScene.seed", &seed,
                     "random seed (>= 0): the same seed gives the same scene");
  options.AddDefault("SyntheticScene.supersampling", &scene.supersampling,
                     "s x s colour samples per pixel");
  options.AddDefault("SyntheticScene.write_proxy_mesh", &scene.write_proxy_mesh,
                     "also write the ground-truth mesh as meshed-delaunay.ply");
  options.AddDefault("SyntheticScene.focal_factor", &scene.focal_factor,
                     "focal length in pixels divided by the width");
  options.AddDefault("SyntheticScene.path_step_degrees", &scene.path_step_degrees,
                     "arc of the camera path between consecutive views");
  options.AddDefault("SyntheticScene.num_sparse_points", &scene.num_sparse_points,
                     "ground-truth 3D points in the sparse model");
  options.AddDefault("SyntheticScene.plain_walls", &scene.plain_walls,
                     "walls, floor and ceiling of one plain colour each (textureless)");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(output_path, "view_synthesis_synthetic");
  Require(seed >= 0, "SyntheticScene.seed", "must be >= 0, got " + std::to_string(seed));
  scene.seed = static_cast<uint64_t>(seed);
  scene.Check();

  Timer timer;
  if (!camera_path.empty()) {
    std::vector<std::pair<std::string, PinholeCamera>> frames;
    for (const TargetCamera& t : ReadNerfstudioCameraPath(camera_path)) {
      frames.emplace_back(t.name, t.camera);
    }
    RenderSyntheticFrames(scene, frames, output_path);
    std::cout << "Wrote the ground truth of " << frames.size() << " frames of "
              << camera_path << " to " << output_path << " in " << timer.Seconds() << " s"
              << std::endl;
    return 0;
  }
  GenerateSyntheticScene(scene, output_path);
  std::cout << "Wrote a synthetic scene of " << scene.num_views << " views ("
            << scene.width << "x" << scene.height << ", seed " << scene.seed << ") to "
            << output_path << " in " << timer.Seconds() << " s" << std::endl;
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_synthetic",
                     "Generate a synthetic scene with exact ground truth",
                     RunViewSynthesisSynthetic);

}  // namespace fvs
