#include "fvs/render/prepare.h"

#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {

PreparedTarget PrepareTarget(const Scene& scene, const TargetView& target,
                             const RenderOptions& options) {
  options.Check();
  Require(
      target.camera.IsValid(), target.name,
      "invalid target camera (non-finite pose, zero size or non-positive focal length)");
  PreparedTarget prepared;
  Timer timer;
  prepared.depth = scene.RenderDepth(target.camera);
  prepared.timings.depth_s = timer.Seconds();

  timer.Restart();
  SourceSelectionOptions selection;
  selection.k = options.num_sources;
  selection.depth_tolerance = options.selection_tolerance;
  selection.exclude = target.exclude_views;
  selection.stride = options.selection_stride;
  selection.num_threads = options.num_threads;
  prepared.sources = SelectSources(scene, target.camera, prepared.depth, selection);
  prepared.timings.selection_s = timer.Seconds();

  timer.Restart();
  WarpOptions warp;
  warp.occlusion_tolerance = options.warp_tolerance;
  warp.num_threads = options.num_threads;
  for (const SourceScore& s : prepared.sources) {
    prepared.warps.push_back(ComputeWarpMap(target.camera, prepared.depth,
                                            scene.view(s.view_index).camera,
                                            scene.SourceDepth(s.view_index), warp));
  }
  prepared.timings.warp_s = timer.Seconds();
  return prepared;
}

}  // namespace fvs
