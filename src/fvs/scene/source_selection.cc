#include "fvs/scene/source_selection.h"

#include <algorithm>
#include <cmath>

#include "fvs/scene/scene.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {

void SourceSelectionOptions::Check() const {
  Require(k >= 1, "source selection", "the number of sources must be at least 1");
  Require(depth_tolerance > 0 && std::isfinite(depth_tolerance), "source selection",
          "depth_tolerance must be positive");
  Require(stride >= 1, "source selection", "stride must be at least 1");
}

int64_t CountVisibleTargetPixels(const PinholeCamera& target, const Image& target_depth,
                                 const PinholeCamera& source, const Image& source_depth,
                                 double depth_tolerance, int stride) {
  Require(target_depth.width == target.width && target_depth.height == target.height,
          "source selection", "target depth size does not match the target camera");
  Require(source_depth.width == source.width && source_depth.height == source.height,
          "source selection", "source depth size does not match the source camera");
  const Eigen::Matrix3d R_rel = source.R * target.R.transpose();
  const Eigen::Vector3d t_rel = source.t - R_rel * target.t;
  int64_t count = 0;
  for (int y = 0; y < target.height; y += stride) {
    const double ny = (y + 0.5 - target.cy) / target.fy;
    for (int x = 0; x < target.width; x += stride) {
      const float d = target_depth.at(x, y);
      if (!(d > 0 && std::isfinite(d))) continue;  // only surface pixels vote
      const double nx = (x + 0.5 - target.cx) / target.fx;
      const Eigen::Vector3d X = R_rel * Eigen::Vector3d(nx * d, ny * d, d) + t_rel;
      if (!(X.z() > 0)) continue;
      const double u = source.fx * X.x() / X.z() + source.cx;
      const double v = source.fy * X.y() / X.z() + source.cy;
      if (!(u >= 0 && v >= 0 && u < source.width && v < source.height)) continue;
      const float ds = source_depth.at(std::min(static_cast<int>(u), source.width - 1),
                                       std::min(static_cast<int>(v), source.height - 1));
      if (!(ds > 0 && std::isfinite(ds))) continue;
      if (std::abs(X.z() - ds) <= depth_tolerance * X.z()) ++count;
    }
  }
  return count;
}

std::vector<SourceScore> SelectSources(const PinholeCamera& target,
                                       const Image& target_depth,
                                       const std::vector<PinholeCamera>& sources,
                                       const std::vector<const Image*>& source_depths,
                                       const SourceSelectionOptions& options) {
  options.Check();
  Require(target.IsValid(), "source selection", "invalid target camera");
  Require(sources.size() == source_depths.size(), "source selection",
          "one depth per source is needed");
  int64_t surface = 0;
  for (int y = 0; y < target_depth.height; y += options.stride) {
    for (int x = 0; x < target_depth.width; x += options.stride) {
      const float d = target_depth.at(x, y);
      surface += d > 0 && std::isfinite(d);
    }
  }
  std::vector<SourceScore> scores(sources.size());
  // One source per task: sources are many and alike in cost.
  ParallelFor(
      0, static_cast<int64_t>(sources.size()),
      [&](int64_t i) {
        scores[i].view_index = static_cast<int>(i);
        if (std::find(options.exclude.begin(), options.exclude.end(), i) !=
            options.exclude.end()) {
          return;
        }
        scores[i].count =
            CountVisibleTargetPixels(target, target_depth, sources[i], *source_depths[i],
                                     options.depth_tolerance, options.stride);
      },
      options.num_threads);
  std::vector<SourceScore> kept;
  for (SourceScore& s : scores) {
    if (s.count <= 0) continue;
    s.fraction = surface > 0 ? static_cast<double>(s.count) / surface : 0.0;
    s.count *= static_cast<int64_t>(options.stride) * options.stride;
    kept.push_back(s);
  }
  // Ties broken by index so the choice is deterministic.
  std::sort(kept.begin(), kept.end(), [](const SourceScore& a, const SourceScore& b) {
    return a.count != b.count ? a.count > b.count : a.view_index < b.view_index;
  });
  if (static_cast<int>(kept.size()) > options.k) kept.resize(options.k);
  return kept;
}

std::vector<SourceScore> SelectSources(const Scene& scene,
                                       const PinholeCamera& target_camera,
                                       const Image& target_depth,
                                       const SourceSelectionOptions& options) {
  std::vector<PinholeCamera> cameras;
  std::vector<const Image*> depths;
  for (int i = 0; i < scene.num_views(); ++i) {
    cameras.push_back(scene.view(i).camera);
    depths.push_back(&scene.SourceDepth(i));
  }
  return SelectSources(target_camera, target_depth, cameras, depths, options);
}

std::vector<SourceScore> SelectSources(const Scene& scene,
                                       const PinholeCamera& target_camera,
                                       const Image& target_depth, int k,
                                       double depth_tolerance) {
  SourceSelectionOptions options;
  options.k = k;
  options.depth_tolerance = depth_tolerance;
  return SelectSources(scene, target_camera, target_depth, options);
}

}  // namespace fvs
