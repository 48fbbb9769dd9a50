// `nearest`: the best-ranked source alone, reprojected through the target depth; pixels
// without a surface take its colour where it sees them at infinity (geometry/warp.h), as
// the others where it sees their surface.
#include <algorithm>
#include <cmath>

#include "fvs/render/prepare.h"
#include "fvs/render/ulr.h"
#include "fvs/scene/scene.h"
#include "fvs/util/parallel.h"

namespace fvs {

namespace {

class NearestMethod : public PixelBlendMethod {
 public:
  explicit NearestMethod(const RenderOptions& options) : PixelBlendMethod(options) {
    // Only the best source is used: warping the others would be wasted work.
    options_.num_sources = 1;
  }
  std::string name() const override { return "nearest"; }

 private:
  void Blend(const Scene& scene, const TargetView& target, const PreparedTarget& prepared,
             RenderResult* out) const override {
    RenderResult& result = *out;
    const int w = target.camera.width, h = target.camera.height;
    if (!prepared.sources.empty()) {
      const Image& photo = scene.SourceImage(prepared.sources[0].view_index);
      const WarpMap& warp = prepared.warps[0];
      const bool bicubic = options_.interpolation == "bicubic";
      ParallelFor(
          0, h,
          [&](int64_t y) {
            float sample[4];
            for (int x = 0; x < w; ++x) {
              const size_t i = static_cast<size_t>(y) * w + x;
              if (warp.valid_warp.data[i] <= 0) continue;
              const double su = warp.source_xy.data[2 * i];
              const double sv = warp.source_xy.data[2 * i + 1];
              if (bicubic) {
                SampleBicubic(photo, su, sv, sample);
              } else {
                SampleBilinear(photo, su, sv, sample, true);
              }
              for (int c = 0; c < 3; ++c) {
                const float v = std::isfinite(sample[c]) ? sample[c] : 0.f;
                result.color.data[3 * i + c] = std::clamp(v, 0.f, 1.f);
              }
              result.coverage.data[i] = 1.f;
              result.confidence.data[i] = 1.f;
            }
          },
          options_.num_threads);
    }
  }
};

}  // namespace

std::unique_ptr<Method> CreateNearestMethod(const RenderOptions& options) {
  return std::make_unique<NearestMethod>(options);
}

}  // namespace fvs
