#include "fvs/render/prepare.h"

#include <algorithm>
#include <utility>

#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {

std::vector<SourceScore> ApplySourceHysteresis(std::vector<SourceScore> ranked,
                                               const std::vector<int>& preferred,
                                               double hysteresis, int k) {
  const auto boosted = [&](const SourceScore& s) {
    const bool favoured =
        std::find(preferred.begin(), preferred.end(), s.view_index) != preferred.end();
    return static_cast<double>(s.count) * (favoured ? 1.0 + hysteresis : 1.0);
  };
  // Stable: equal boosted scores keep the selection's order (best count first).
  std::stable_sort(ranked.begin(), ranked.end(),
                   [&](const SourceScore& a, const SourceScore& b) {
                     return boosted(a) > boosted(b);
                   });
  if (static_cast<int>(ranked.size()) > k) ranked.resize(k);
  return ranked;
}

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
  selection.adaptive = options.num_sources == 0;
  selection.k = selection.adaptive ? options.max_num_sources : options.num_sources;
  selection.depth_tolerance = options.selection_tolerance;
  selection.exclude = target.exclude_views;
  selection.stride = options.selection_stride;
  selection.num_threads = options.num_threads;
  const SourceRanking ranking =
      RankSources(scene, target.camera, prepared.depth, selection);
  const bool hysteresis =
      options.source_hysteresis > 0 && !target.preferred_sources.empty();
  // The hysteresis reorders the ranking, blurry photos go last; the choice (top K or
  // adaptive) follows that order.
  std::vector<SourceScore> order =
      hysteresis ? ApplySourceHysteresis(ranking.ranked, target.preferred_sources,
                                         options.source_hysteresis,
                                         static_cast<int>(ranking.ranked.size()))
                 : ranking.ranked;
  if (!options.use_blurry_sources) {
    std::stable_partition(order.begin(), order.end(), [&](const SourceScore& s) {
      return !scene.view(s.view_index).blurry;
    });
  }
  prepared.sources = ChooseSources(ranking, order, selection);
  if (options.stable_source_order) {
    std::sort(prepared.sources.begin(), prepared.sources.end(),
              [](const SourceScore& a, const SourceScore& b) {
                return a.view_index < b.view_index;
              });
  }
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

PixelBlendMethod::PixelBlendMethod(const RenderOptions& options) : options_(options) {
  options_.Check();
}

RenderResult PixelBlendMethod::Render(const Scene& scene, const TargetView& target) {
  PreparedTarget prepared = PrepareTarget(scene, target, options_);
  Timer timer;
  RenderResult result;
  result.timings = prepared.timings;
  result.sources = prepared.sources;
  const int w = target.camera.width, h = target.camera.height;
  result.color = Image(w, h, 3);
  result.confidence = Image(w, h, 1);
  result.coverage = Image(w, h, 1);
  Blend(scene, target, prepared, &result);
  result.depth = std::move(prepared.depth);
  result.infinity = AtInfinityMask(result.depth, result.coverage);
  result.timings.blend_s = timer.Seconds();
  return result;
}

}  // namespace fvs
