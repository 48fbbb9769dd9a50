#include "fvs/render/ulr.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <vector>

#include "fvs/render/prepare.h"
#include "fvs/scene/scene.h"
#include "fvs/util/parallel.h"

namespace fvs {

namespace {

class UlrMethod : public PixelBlendMethod {
 public:
  explicit UlrMethod(const RenderOptions& options) : PixelBlendMethod(options) {}
  std::string name() const override { return "ulr"; }

 private:
  void Blend(const Scene& scene, const TargetView& target, const PreparedTarget& prepared,
             RenderResult* out) const override {
    RenderResult& result = *out;
    const PinholeCamera& cam = target.camera;
    const int w = cam.width, h = cam.height;
    const int n = static_cast<int>(prepared.sources.size());
    std::vector<const Image*> photos;
    for (const SourceScore& s : prepared.sources) {
      photos.push_back(&scene.SourceImage(s.view_index));
    }
    const UlrSources ulr_sources = MakeUlrSources(scene, target, prepared);
    const double far_distance = UlrFarDistance(ulr_sources);
    UlrOptions settings;
    settings.resolution_weight = options_.ulr_resolution_weight;
    settings.num_blend = options_.ulr_num_blend;
    const bool bicubic = options_.interpolation == "bicubic";
    ParallelFor(
        0, h,
        [&](int64_t y) {
          std::vector<double> weights(n);
          std::unique_ptr<bool[]> sees(new bool[n]);
          float sample[4];
          for (int x = 0; x < w; ++x) {
            const size_t i = static_cast<size_t>(y) * w + x;
            const Eigen::Vector3d point =
                UlrSurfacePoint(cam, prepared.depth, x, y, far_distance);
            for (int s = 0; s < n; ++s)
              sees[s] = prepared.warps[s].valid_warp.data[i] > 0;
            const int m =
                UlrPointWeights(point, ulr_sources, sees.get(), settings, weights.data());
            if (m == 0) continue;
            double rgb[3] = {0, 0, 0};
            for (int s = 0; s < n; ++s) {
              if (weights[s] <= 0) continue;
              const Image& src_xy = prepared.warps[s].source_xy;
              if (bicubic) {
                SampleBicubic(*photos[s], src_xy.data[2 * i], src_xy.data[2 * i + 1],
                              sample);
              } else {
                SampleBilinear(*photos[s], src_xy.data[2 * i], src_xy.data[2 * i + 1],
                               sample, true);
              }
              for (int c = 0; c < 3; ++c) rgb[c] += weights[s] * sample[c];
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
  }
};

}  // namespace

Eigen::Vector3d UlrSurfacePoint(const PinholeCamera& target, const Image& depth, int x,
                                int y, double far_distance) {
  const float d = depth.data[static_cast<size_t>(y) * depth.width + x];
  if (d > 0 && std::isfinite(d)) return target.PixelToCamera(x + 0.5, y + 0.5, d);
  return UlrPointAtInfinity(target.PixelToCamera(x + 0.5, y + 0.5, 1.0), far_distance);
}

UlrSources MakeUlrSources(const Scene& scene, const TargetView& target,
                          const PreparedTarget& prepared) {
  const PinholeCamera& cam = target.camera;
  UlrSources out;
  out.target_focal = std::sqrt(cam.fx * cam.fy);
  for (const SourceScore& s : prepared.sources) {
    const PinholeCamera& src = scene.view(s.view_index).camera;
    out.centers.push_back(cam.WorldToCamera(src.Center()));
    out.focals.push_back(std::sqrt(src.fx * src.fy));
  }
  return out;
}

std::unique_ptr<Method> CreateUlrMethod(const RenderOptions& options) {
  return std::make_unique<UlrMethod>(options);
}

}  // namespace fvs
