// colmap view_synthesis_refine --workspace_path W --minutes M: refines the proxy mesh of
// one prepared scene by the photo-consistency of its leave-one-out renders within M
// minutes of wall time, into W/fvs/refine/mesh.ply, which view_synthesis,
// view_synthesis_eval, view_synthesis_path and the GUI then use by default
// (train/scene_refine.h). Needs no trained model.
#include <iomanip>
#include <iostream>

#include "fvs/exe/command_registry.h"
#include "fvs/train/scene_refine.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunViewSynthesisRefine(int argc, char** argv) {
  SceneRefineOptions o;
  MeshPhotoRefineOptions& r = o.refine;
  OptionManager options(
      "view_synthesis_refine",
      "Refine one prepared scene's proxy mesh by the photo-consistency of its "
      "leave-one-out renders within a time budget (photos held out at prepare are never "
      "used); every renderer then uses it.");
  options.AddRequired("workspace_path", &o.workspace_path,
                      "prepared workspace (view_synthesis_prepare)");
  options.AddDefault("minutes", &o.minutes,
                     "wall-time budget of the whole command; rerun with more to go on");
  options.AddDefault("Refine.pack_scale", &o.pack_scale,
                     "image scale of the working copy of the scene (1 = as rendered)");
  options.AddDefault("Refine.num_sources", &r.num_sources, "sources per target photo");
  options.AddDefault("Refine.pixels_per_step", &r.pixels_per_step,
                     "pixels sampled per optimiser step, over all photos");
  options.AddDefault("Refine.step", &r.step, "Adam step, in median edge lengths");
  options.AddDefault("Refine.smoothness", &r.smoothness,
                     "weight of the Laplacian term on the vertex moves");
  options.AddDefault("Refine.max_move", &r.max_move,
                     "largest vertex move, in median edge lengths");
  options.AddDefault("Refine.steps_per_raster", &r.steps_per_raster,
                     "steps between re-rasterisations (faces, visibility, weights)");
  options.AddDefault("Refine.coarse_levels", &r.coarse_levels,
                     "blurred levels before the sharp photos (radius 2^L ... 2 px)");
  options.AddDefault("Refine.num_threads", &r.num_threads, "<= 0: all cores");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(o.workspace_path, "view_synthesis_refine");
  const SceneRefineSummary s = RunSceneRefine(o);
  if (s.already_done) {
    std::cerr << "refined mesh: " << s.mesh_path
              << " is refined for this budget already (" << s.steps
              << " steps); nothing to do\n";
    return 0;
  }
  std::cerr << std::fixed << std::setprecision(4) << "refined mesh: " << s.mesh_path
            << " (" << s.steps << " steps, photo error " << s.last.initial_error << " -> "
            << s.last.final_error << ", median move " << std::setprecision(2)
            << s.last.median_move << " edges, " << std::setprecision(0) << s.seconds
            << " s in all); view_synthesis, view_synthesis_eval, view_synthesis_path and "
               "the GUI on "
            << o.workspace_path << " now render with it\n";
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND(
    "view_synthesis_refine",
    "refine one scene's proxy mesh by the photo-consistency of its renders (resumable)",
    RunViewSynthesisRefine);

}  // namespace fvs
