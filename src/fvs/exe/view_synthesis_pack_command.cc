// colmap view_synthesis_pack --workspace_path W --output_path T [--scale 0.25]: turns a
// prepared scene into the trainer's packed form T/scene.safetensors (train/pack.h,
// doc/training.md): photos and mesh depths at `scale`, cameras, the N x N overlap matrix.
// The folder travels to a GPU machine on its own.
#include <iostream>

#include "fvs/exe/command_registry.h"
#include "fvs/scene/scene.h"
#include "fvs/train/pack.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunViewSynthesisPack(int argc, char** argv) {
  std::string workspace_path, output_path;
  PackOptions pack;
  int num_threads = -1;
  OptionManager options(
      "view_synthesis_pack",
      "Pack a prepared scene for training: T/scene.safetensors with images "
      "and mesh depths at --scale, cameras and view overlaps.");
  options.AddRequired("workspace_path", &workspace_path,
                      "prepared dense workspace (view_synthesis_prepare)");
  options.AddRequired("output_path", &output_path, "folder of the packed scene");
  options.AddDefault("scale", &pack.scale, "image scale (0.25: quarter resolution)");
  options.AddDefault("depth_tolerance", &pack.depth_tolerance,
                     "relative depth tolerance of the overlap ranking");
  options.AddDefault("num_threads", &num_threads, "-1 = all cores");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(output_path, "view_synthesis_pack");
  pack.num_threads = num_threads;
  pack.Check();
  SceneLoadOptions load;
  load.num_threads = num_threads;
  const Scene scene = Scene::Load(workspace_path, load);
  const PackSummary summary = PackScene(scene, pack, output_path);
  std::cerr << "packed " << summary.num_views << " views at " << summary.width << "x"
            << summary.height << " into " << summary.path << " (mean overlap "
            << summary.mean_overlap << ", " << summary.seconds << " s)\n";
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND(
    "view_synthesis_pack",
    "pack a prepared scene into a training set folder (scene.safetensors)",
    RunViewSynthesisPack);

}  // namespace fvs
