// Source selection: which registered views see most of what a target camera sees.
// The target depth (rendered from the proxy mesh) is unprojected pixel by pixel; a source
// scores one for every target surface pixel that lands inside it, in front of it, and
// within depth_tolerance (relative, 10% as the reference code's ranking) of the source's
// own depth at the nearest source pixel. The top K by count are returned, best first;
// sources that see nothing (count 0) are never returned, so they are never encoded.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs {

class Scene;

struct SourceScore {
  int view_index = -1;  // into Scene::views()
  int64_t count = 0;    // target pixels the source sees
  double fraction = 0;  // count / target surface pixels
};

struct SourceSelectionOptions {
  int k = 5;
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

// Ranks the given sources; cameras and depths are in one (scene-centred) frame.
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
