// Source selection: which registered views see most of what a target camera sees.
// The target depth (rendered from the proxy mesh) is unprojected pixel by pixel; a source
// scores one for every target surface pixel that lands inside it, in front of it, and
// within depth_tolerance (relative, 10% as the reference code's ranking) of the source's
// own depth at the nearest source pixel. Target pixels without a surface look at the
// background beyond the mesh: a source sees one when the pixel's direction, rotated into
// the source (no translation at infinity), lands inside it where it has no surface
// either (the warp's test, geometry/warp.h). Sources rank by surface count, then by
// background count, so a target of sky alone still gets the sources that see its sky;
// sources that see nothing are never returned, so they are never encoded.
//
// How many: a fixed K (the top K), or, with `adaptive`, per target: sources are taken in
// ranking order while they add coverage. The first min_k are taken; each later one only
// if it sees at least min_gain of the target's pixels that fewer than wanted_views of the
// sources taken so far see (a pixel wants several views: the blend picks among them by
// angle and agreement); at most k. A source that adds too little is passed over (not
// encoded) and the next one is tried.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs {

class Scene;

struct SourceScore {
  int view_index = -1;         // into Scene::views()
  int64_t count = 0;           // target surface pixels the source sees
  int64_t infinity_count = 0;  // target pixels without surface it sees at infinity
  double fraction = 0;         // count / target surface pixels
};

struct SourceSelectionOptions {
  int k = 5;  // the number of sources; with adaptive, the most
  bool adaptive = false;
  // The adaptive rule (see the top of this file). Defaults chosen on leave-one-out views
  // of three training scenes (doc/evaluation.md, adaptive K): a source is worth adding
  // for pixels no source sees yet; asking for more views per pixel added sources that
  // blurred the blend.
  int min_k = 2;
  int wanted_views = 1;
  double min_gain = 0.005;  // fraction of the target's pixels
  double depth_tolerance = 0.1;
  // Views never selected (e.g. the held-out target itself in an evaluation).
  std::vector<int> exclude;
  // Every stride-th target pixel in x and y is tested (1 = all); counts are scaled back.
  int stride = 1;
  int num_threads = 0;  // <= 0: DefaultNumThreads()
  void Check() const;
};

// The count of one source (the unit the selection is built from; exposed for tests).
int64_t CountVisibleTargetPixels(const PinholeCamera& target, const Image& target_depth,
                                 const PinholeCamera& source, const Image& source_depth,
                                 double depth_tolerance, int stride = 1);

// Every source that sees something of the target, ranked best first, and, when
// options.adaptive, which of the (stride-sampled) target pixels each one sees.
struct SourceRanking {
  std::vector<SourceScore> ranked;
  // By view index: bit i set when the source sees sampled pixel i (row-major over the
  // sampled grid); empty for sources that see nothing or when not adaptive.
  std::vector<std::vector<uint64_t>> seen;
  int64_t num_pixels = 0;  // sampled target pixels, surface or not
};

SourceRanking RankSources(const PinholeCamera& target, const Image& target_depth,
                          const std::vector<PinholeCamera>& sources,
                          const std::vector<const Image*>& source_depths,
                          const SourceSelectionOptions& options);
SourceRanking RankSources(const Scene& scene, const PinholeCamera& target_camera,
                          const Image& target_depth,
                          const SourceSelectionOptions& options);

// The chosen sources, in the order of `order` (the ranking's sources, reordered, e.g.
// by ApplySourceHysteresis): its first options.k, or the adaptive rule's choice.
std::vector<SourceScore> ChooseSources(const SourceRanking& ranking,
                                       const std::vector<SourceScore>& order,
                                       const SourceSelectionOptions& options);

// RankSources then ChooseSources in ranking order; cameras and depths are in one
// (scene-centred) frame.
std::vector<SourceScore> SelectSources(const PinholeCamera& target,
                                       const Image& target_depth,
                                       const std::vector<PinholeCamera>& sources,
                                       const std::vector<const Image*>& source_depths,
                                       const SourceSelectionOptions& options);

std::vector<SourceScore> SelectSources(const Scene& scene,
                                       const PinholeCamera& target_camera,
                                       const Image& target_depth, int k,
                                       double depth_tolerance = 0.1);
std::vector<SourceScore> SelectSources(const Scene& scene,
                                       const PinholeCamera& target_camera,
                                       const Image& target_depth,
                                       const SourceSelectionOptions& options);

}  // namespace fvs
