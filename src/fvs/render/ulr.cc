#include "fvs/render/ulr.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "fvs/render/prepare.h"
#include "fvs/scene/scene.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace fvs {

namespace {

// Below this a penalty counts as zero: keeps 1 / p finite and lets an exact match
// dominate.
constexpr double kMinPenalty = 1e-6;

class UlrMethod : public Method {
 public:
  explicit UlrMethod(const RenderOptions& options) : options_(options) {
    options_.Check();
  }
  std::string name() const override { return "ulr"; }

  RenderResult Render(const Scene& scene, const TargetView& target) override {
    PreparedTarget prepared = PrepareTarget(scene, target, options_);
    RenderResult result;
    result.timings = prepared.timings;
    result.sources = prepared.sources;
    Timer timer;
    const PinholeCamera& cam = target.camera;
    const int w = cam.width, h = cam.height;
    const int n = static_cast<int>(prepared.sources.size());
    std::vector<const Image*> photos;
    std::vector<Eigen::Vector3d> centers;  // source centres in the target camera frame
    std::vector<double> focals;
    for (const SourceScore& s : prepared.sources) {
      photos.push_back(&scene.SourceImage(s.view_index));
      const PinholeCamera& src = scene.view(s.view_index).camera;
      centers.push_back(cam.WorldToCamera(src.Center()));
      focals.push_back(std::sqrt(src.fx * src.fy));
    }
    const double target_focal = std::sqrt(cam.fx * cam.fy);
    const WarpOptions warp_defaults;
    result.color = Image(w, h, 3);
    result.confidence = Image(w, h, 1);
    result.coverage = Image(w, h, 1);
    ParallelFor(
        0, h,
        [&](int64_t y) {
          std::vector<double> penalties(n), weights(n);
          std::vector<int> which(n);
          float sample[4];
          for (int x = 0; x < w; ++x) {
            const size_t i = static_cast<size_t>(y) * w + x;
            int m = 0;
            const double d =
                EffectiveDepth(prepared.depth.data[i], warp_defaults.invalid_depth);
            const Eigen::Vector3d point = cam.PixelToCamera(x + 0.5, y + 0.5, d);
            for (int s = 0; s < n; ++s) {
              if (prepared.warps[s].valid_warp.data[i] <= 0) continue;
              penalties[m] =
                  UlrPenalty(point, Eigen::Vector3d::Zero(), target_focal, centers[s],
                             focals[s], options_.ulr_resolution_weight);
              which[m++] = s;
            }
            if (m == 0) continue;
            UlrWeights(penalties.data(), m, options_.ulr_num_blend, weights.data());
            double rgb[3] = {0, 0, 0};
            for (int j = 0; j < m; ++j) {
              if (weights[j] <= 0) continue;
              const Image& src_xy = prepared.warps[which[j]].source_xy;
              SampleBilinear(*photos[which[j]], src_xy.data[2 * i],
                             src_xy.data[2 * i + 1], sample, true);
              for (int c = 0; c < 3; ++c) rgb[c] += weights[j] * sample[c];
            }
            for (int c = 0; c < 3; ++c) {
              const double v = std::isfinite(rgb[c]) ? rgb[c] : 0.0;
              result.color.data[3 * i + c] = static_cast<float>(std::clamp(v, 0.0, 1.0));
            }
            result.coverage.data[i] = 1.f;
            // Share of the selected sources that see the pixel.
            result.confidence.data[i] = static_cast<float>(m) / n;
          }
        },
        options_.num_threads);
    result.depth = std::move(prepared.depth);
    result.timings.blend_s = timer.Seconds();
    return result;
  }

 private:
  RenderOptions options_;
};

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

std::unique_ptr<Method> CreateUlrMethod(const RenderOptions& options) {
  return std::make_unique<UlrMethod>(options);
}

}  // namespace fvs
