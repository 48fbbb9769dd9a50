#include "fvs/net/ulr_weights.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>

#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {

void UlrOptions::Check() const {
  Require(std::isfinite(resolution_weight) && resolution_weight >= 0, "ULR options",
          "resolution_weight must be finite and >= 0");
  Require(num_blend >= 1, "ULR options", "num_blend must be at least 1");
}

namespace {

// Below this a penalty counts as zero: keeps 1 / p finite and lets an exact match
// dominate.
constexpr double kMinPenalty = 1e-6;

}  // namespace

double UlrPenalty(const Eigen::Vector3d& point, const Eigen::Vector3d& target_center,
                  double target_focal, const Eigen::Vector3d& source_center,
                  double source_focal, double resolution_weight) {
  const Eigen::Vector3d a = target_center - point;
  const Eigen::Vector3d b = source_center - point;
  // atan2 of |a x b| and a.b: accurate for tiny and for near-straight angles alike.
  const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
  const double ta = a.norm() / target_focal, tb = b.norm() / source_focal;
  const double resolution = ta > 0 ? std::max(0.0, tb / ta - 1.0) : 0.0;
  const double p = angle + resolution_weight * resolution;
  return std::isfinite(p) ? std::max(p, 0.0) : M_PI;
}

double UlrFarDistance(const UlrSources& sources) {
  double farthest = 0;
  for (const Eigen::Vector3d& c : sources.centers)
    farthest = std::max(farthest, c.norm());
  const double d = kUlrFarFactor * farthest;
  return d > 0 && std::isfinite(d) ? d : 1.0;
}

Eigen::Vector3d UlrPointAtInfinity(const Eigen::Vector3d& ray, double far_distance) {
  const double n = ray.norm();
  if (!(n > 0 && std::isfinite(n))) return Eigen::Vector3d(0, 0, far_distance);
  return ray * (far_distance / n);
}

void UlrWeights(const double* penalties, int n, int k, double* weights) {
  if (n <= 0) return;
  k = std::max(1, k);
  std::vector<double> sorted(penalties, penalties + n);
  std::sort(sorted.begin(), sorted.end());
  const double threshold = n > k ? sorted[k] : 2.0 * sorted[n - 1] + kMinPenalty;
  double sum = 0;
  for (int j = 0; j < n; ++j) {
    const double p = std::max(penalties[j], kMinPenalty);
    const double w =
        threshold > 0 ? std::max(0.0, 1.0 - penalties[j] / threshold) / p : 0.0;
    weights[j] = w;
    sum += w;
  }
  if (sum > 0 && std::isfinite(sum)) {
    for (int j = 0; j < n; ++j) weights[j] /= sum;
    return;
  }
  // Ties at the threshold (all weights 0): share equally among the best.
  int best = 0;
  for (int j = 0; j < n; ++j) best += penalties[j] <= sorted[0];
  for (int j = 0; j < n; ++j) weights[j] = penalties[j] <= sorted[0] ? 1.0 / best : 0.0;
}

int UlrPointWeights(const Eigen::Vector3d& point, const UlrSources& sources,
                    const bool* sees, const UlrOptions& settings, double* weights) {
  const int n = sources.size();
  // Small fixed buffers: K is a handful; larger K falls back to the heap.
  double penalty_buffer[32], weight_buffer[32];
  int which_buffer[32];
  std::vector<double> penalty_heap, weight_heap;
  std::vector<int> which_heap;
  double* penalties = penalty_buffer;
  double* compact = weight_buffer;
  int* which = which_buffer;
  if (n > 32) {
    penalty_heap.resize(n);
    weight_heap.resize(n);
    which_heap.resize(n);
    penalties = penalty_heap.data();
    compact = weight_heap.data();
    which = which_heap.data();
  }
  int m = 0;
  for (int s = 0; s < n; ++s) {
    weights[s] = 0;
    if (!sees[s]) continue;
    penalties[m] =
        UlrPenalty(point, Eigen::Vector3d::Zero(), sources.target_focal,
                   sources.centers[s], sources.focals[s], settings.resolution_weight);
    which[m++] = s;
  }
  if (m == 0) return 0;
  UlrWeights(penalties, m, settings.num_blend, compact);
  for (int j = 0; j < m; ++j) weights[which[j]] = compact[j];
  return m;
}

void UlrLogWeights(const double* points, int64_t num_pixels, const UlrSources& sources,
                   const float* sees, const UlrOptions& settings, float* log_weights,
                   int num_threads) {
  const int n = sources.size();
  const float floor = static_cast<float>(std::log(kUlrWeightFloor));
  ParallelForRanges(
      0, num_pixels,
      [&](int64_t begin, int64_t end, int) {
        std::vector<double> weights(n);
        std::unique_ptr<bool[]> seen(new bool[n]);
        for (int64_t i = begin; i < end; ++i) {
          for (int s = 0; s < n; ++s) seen[s] = sees[s * num_pixels + i] > 0.5f;
          const Eigen::Vector3d point(points[3 * i], points[3 * i + 1],
                                      points[3 * i + 2]);
          UlrPointWeights(point, sources, seen.get(), settings, weights.data());
          for (int s = 0; s < n; ++s) {
            const double w = weights[s];
            log_weights[s * num_pixels + i] =
                w > kUlrWeightFloor ? static_cast<float>(std::log(w)) : floor;
          }
        }
      },
      num_threads);
}

}  // namespace fvs
