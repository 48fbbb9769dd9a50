// Per-scene refinement of a prepared workspace within a time budget
// (`colmap view_synthesis_refine`, issue 41): the proxy mesh is refined by the
// photo-consistency of its leave-one-out renders (train/mesh_photo_refine.h). The photos
// held out of the geometry at prepare (W/fvs/holdout.txt) are never a target nor a
// source, so view_synthesis_eval --protocol holdout afterwards still scores views the
// method never saw. Files:
//   W/fvs/refine/pack/          the scene packed at pack_scale (train/pack.h)
//   W/fvs/refine/checkpoint.ply the mesh so far, every minute (a killed run resumes)
//   W/fvs/refine/state.json     the mesh refined, the minutes and steps spent
//   W/fvs/refine/mesh.ply       the result, which every renderer then uses
//                               (DenseWorkspace::ProxyMeshPath), and refine.json, its
//                               card
// A rerun with a larger budget goes on from where the last one stopped; the same budget
// again does nothing; a prepare that meshes again makes the result stale (it is then
// ignored by the renderers and redone by the next refine).
#pragma once

#include <string>

#include "fvs/train/mesh_photo_refine.h"

namespace fvs {

struct SceneRefineOptions {
  std::string workspace_path;
  double minutes = 10;      // wall-time budget of everything the command does
  double pack_scale = 1.0;  // of the workspace images; 1 = the resolution renders use
  MeshPhotoRefineOptions refine;  // its `seconds` is set from the budget
  bool quiet = false;
  void Check() const;  // throws fvs::Error
};

struct SceneRefineSummary {
  std::string mesh_path;  // W/fvs/refine/mesh.ply
  bool already_done = false;
  int steps = 0;               // optimiser steps, all runs together
  double seconds = 0;          // wall time of all runs together, packing included
  MeshPhotoRefineResult last;  // this run's (its mesh is the result)
};

// Throws fvs::Error for an unprepared workspace or a scene without usable views.
SceneRefineSummary RunSceneRefine(const SceneRefineOptions& options);

}  // namespace fvs
