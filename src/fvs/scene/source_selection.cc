#include "fvs/scene/source_selection.h"

#include <algorithm>
#include <cmath>

#include "fvs/scene/scene.h"
#include "fvs/geometry/warp.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {

void SourceSelectionOptions::Check() const {
  Require(k >= 1, "source selection", "the number of sources must be at least 1");
  Require(depth_tolerance > 0 && std::isfinite(depth_tolerance), "source selection",
          "depth_tolerance must be positive");
  Require(stride >= 1, "source selection", "stride must be at least 1");
  Require(min_k >= 1, "source selection", "min_k must be at least 1");
  Require(wanted_views >= 1, "source selection", "wanted_views must be at least 1");
  Require(min_gain >= 0 && min_gain <= 1, "source selection",
          "min_gain must be in [0, 1]");
}

namespace {

// What one source sees of the stride-sampled target pixels.
struct Visibility {
  int64_t surface = 0, infinity = 0;
  std::vector<uint64_t> seen;  // filled when asked for
};

Visibility SourceVisibility(const PinholeCamera& target, const Image& target_depth,
                            const PinholeCamera& source, const Image& source_depth,
                            double depth_tolerance, int stride, bool with_infinity,
                            bool with_mask) {
  Require(target_depth.width == target.width && target_depth.height == target.height,
          "source selection", "target depth size does not match the target camera");
  Require(source_depth.width == source.width && source_depth.height == source.height,
          "source selection", "source depth size does not match the source camera");
  const Eigen::Matrix3d R_rel = source.R * target.R.transpose();
  const Eigen::Vector3d t_rel = source.t - R_rel * target.t;
  const int64_t cols = (target.width + stride - 1) / stride;
  const int64_t rows = (target.height + stride - 1) / stride;
  Visibility v;
  if (with_mask) v.seen.assign((cols * rows + 63) / 64, 0);
  int64_t i = -1;  // sampled pixel index
  for (int y = 0; y < target.height; y += stride) {
    const double ny = (y + 0.5 - target.cy) / target.fy;
    for (int x = 0; x < target.width; x += stride) {
      ++i;
      const float d = target_depth.at(x, y);
      const bool surface = d > 0 && std::isfinite(d);
      if (!surface && !with_infinity) continue;
      const double nx = (x + 0.5 - target.cx) / target.fx;
      // At infinity the direction alone, rotated (geometry/warp.h).
      const Eigen::Vector3d X =
          surface ? Eigen::Vector3d(R_rel * Eigen::Vector3d(nx * d, ny * d, d) + t_rel)
                  : Eigen::Vector3d(R_rel * Eigen::Vector3d(nx, ny, 1));
      if (!(X.z() > 0)) continue;
      const double u = source.fx * X.x() / X.z() + source.cx;
      const double s = source.fy * X.y() / X.z() + source.cy;
      if (!(u >= 0 && s >= 0 && u < source.width && s < source.height)) continue;
      bool sees;
      if (surface) {
        const float ds =
            source_depth.at(std::min(static_cast<int>(u), source.width - 1),
                            std::min(static_cast<int>(s), source.height - 1));
        sees = ds > 0 && std::isfinite(ds) &&
               std::abs(X.z() - ds) <= depth_tolerance * X.z();
        v.surface += sees;
      } else {
        sees = SourceSeesInfinity(source_depth, u, s);
        v.infinity += sees;
      }
      if (sees && with_mask) v.seen[i >> 6] |= uint64_t{1} << (i & 63);
    }
  }
  return v;
}

// The adaptive rule of the header, over `order`.
std::vector<SourceScore> ChooseAdaptive(const SourceRanking& ranking,
                                        const std::vector<SourceScore>& order,
                                        const SourceSelectionOptions& options) {
  std::vector<uint8_t> views(ranking.num_pixels, 0);  // chosen sources seeing each pixel
  const double min_pixels = options.min_gain * static_cast<double>(ranking.num_pixels);
  const auto wanted = static_cast<uint8_t>(std::min(options.wanted_views, 255));
  std::vector<SourceScore> chosen;
  for (const SourceScore& s : order) {
    if (static_cast<int>(chosen.size()) >= options.k) break;
    const std::vector<uint64_t>& seen = ranking.seen.at(s.view_index);
    const auto for_each_seen = [&](auto&& fn) {
      for (size_t w = 0; w < seen.size(); ++w) {
        for (uint64_t bits = seen[w]; bits != 0; bits &= bits - 1) {
          fn(static_cast<int64_t>(w * 64 + __builtin_ctzll(bits)));
        }
      }
    };
    if (static_cast<int>(chosen.size()) >= options.min_k) {
      int64_t gain = 0;
      for_each_seen([&](int64_t i) { gain += views[i] < wanted; });
      if (static_cast<double>(gain) < min_pixels || gain == 0) continue;
    }
    for_each_seen([&](int64_t i) { views[i] += views[i] < 255; });
    chosen.push_back(s);
  }
  return chosen;
}

}  // namespace

int64_t CountVisibleTargetPixels(const PinholeCamera& target, const Image& target_depth,
                                 const PinholeCamera& source, const Image& source_depth,
                                 double depth_tolerance, int stride) {
  return SourceVisibility(target, target_depth, source, source_depth, depth_tolerance,
                          stride, /*with_infinity=*/false, /*with_mask=*/false)
      .surface;
}

SourceRanking RankSources(const PinholeCamera& target, const Image& target_depth,
                          const std::vector<PinholeCamera>& sources,
                          const std::vector<const Image*>& source_depths,
                          const SourceSelectionOptions& options) {
  options.Check();
  Require(target.IsValid(), "source selection", "invalid target camera");
  Require(sources.size() == source_depths.size(), "source selection",
          "one depth per source is needed");
  int64_t surface = 0;
  SourceRanking ranking;
  for (int y = 0; y < target_depth.height; y += options.stride) {
    for (int x = 0; x < target_depth.width; x += options.stride) {
      const float d = target_depth.at(x, y);
      surface += d > 0 && std::isfinite(d);
      ++ranking.num_pixels;
    }
  }
  // Background pixels only cost a source test when there are any.
  const bool with_infinity = surface < ranking.num_pixels;
  std::vector<SourceScore> scores(sources.size());
  ranking.seen.resize(sources.size());
  // One source per task: sources are many and alike in cost.
  ParallelFor(
      0, static_cast<int64_t>(sources.size()),
      [&](int64_t i) {
        scores[i].view_index = static_cast<int>(i);
        if (std::find(options.exclude.begin(), options.exclude.end(), i) !=
            options.exclude.end()) {
          return;
        }
        Visibility v = SourceVisibility(target, target_depth, sources[i],
                                        *source_depths[i], options.depth_tolerance,
                                        options.stride, with_infinity, options.adaptive);
        scores[i].count = v.surface;
        scores[i].infinity_count = v.infinity;
        if (v.surface + v.infinity > 0) ranking.seen[i] = std::move(v.seen);
      },
      options.num_threads);
  const int64_t area = int64_t{options.stride} * options.stride;  // counts scaled back
  for (SourceScore& s : scores) {
    if (s.count + s.infinity_count <= 0) continue;
    s.fraction = surface > 0 ? static_cast<double>(s.count) / surface : 0.0;
    s.count *= area;
    s.infinity_count *= area;
    ranking.ranked.push_back(s);
  }
  // Surface first, the background next; ties broken by index so the choice is
  // deterministic.
  std::sort(ranking.ranked.begin(), ranking.ranked.end(),
            [](const SourceScore& a, const SourceScore& b) {
              if (a.count != b.count) return a.count > b.count;
              if (a.infinity_count != b.infinity_count) {
                return a.infinity_count > b.infinity_count;
              }
              return a.view_index < b.view_index;
            });
  return ranking;
}

std::vector<SourceScore> ChooseSources(const SourceRanking& ranking,
                                       const std::vector<SourceScore>& order,
                                       const SourceSelectionOptions& options) {
  options.Check();
  if (options.adaptive) return ChooseAdaptive(ranking, order, options);
  std::vector<SourceScore> chosen = order;
  if (static_cast<int>(chosen.size()) > options.k) chosen.resize(options.k);
  return chosen;
}

std::vector<SourceScore> SelectSources(const PinholeCamera& target,
                                       const Image& target_depth,
                                       const std::vector<PinholeCamera>& sources,
                                       const std::vector<const Image*>& source_depths,
                                       const SourceSelectionOptions& options) {
  const SourceRanking ranking =
      RankSources(target, target_depth, sources, source_depths, options);
  return ChooseSources(ranking, ranking.ranked, options);
}

SourceRanking RankSources(const Scene& scene, const PinholeCamera& target_camera,
                          const Image& target_depth,
                          const SourceSelectionOptions& options) {
  std::vector<PinholeCamera> cameras;
  std::vector<const Image*> depths;
  for (int i = 0; i < scene.num_views(); ++i) {
    cameras.push_back(scene.view(i).camera);
    depths.push_back(&scene.SourceDepth(i));
  }
  return RankSources(target_camera, target_depth, cameras, depths, options);
}

std::vector<SourceScore> SelectSources(const Scene& scene,
                                       const PinholeCamera& target_camera,
                                       const Image& target_depth,
                                       const SourceSelectionOptions& options) {
  const SourceRanking ranking = RankSources(scene, target_camera, target_depth, options);
  return ChooseSources(ranking, ranking.ranked, options);
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
