#include "fvs/render/render_output.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"

namespace fvs {

namespace {

// A compact approximation of the "turbo" colour map (Mikhailov 2019), t in [0, 1].
void Turbo(double t, float* rgb) {
  t = std::clamp(t, 0.0, 1.0);
  const double r =
      0.1357 +
      t * (4.5974 - t * (42.3277 - t * (130.5887 - t * (150.5666 - t * 58.1375))));
  const double g =
      0.0914 + t * (2.1856 + t * (4.8052 - t * (14.0195 - t * (4.2109 + t * 2.7747))));
  const double b =
      0.1067 +
      t * (12.5925 - t * (60.1097 - t * (109.0745 - t * (88.5066 - t * 26.8183))));
  rgb[0] = static_cast<float>(std::clamp(r, 0.0, 1.0));
  rgb[1] = static_cast<float>(std::clamp(g, 0.0, 1.0));
  rgb[2] = static_cast<float>(std::clamp(b, 0.0, 1.0));
}

}  // namespace

Image FalseColourDepth(const Image& depth) {
  Image out(depth.width, depth.height, 3);
  std::vector<float> inv;
  for (float d : depth.data) {
    if (d > 0 && std::isfinite(d)) inv.push_back(1.f / d);
  }
  if (inv.empty()) return out;
  std::sort(inv.begin(), inv.end());
  const double lo = inv[inv.size() * 2 / 100];
  const double hi = inv[std::min(inv.size() - 1, inv.size() * 98 / 100)];
  const double range = hi > lo ? hi - lo : 1.0;
  for (size_t i = 0; i < depth.data.size(); ++i) {
    const float d = depth.data[i];
    if (d > 0 && std::isfinite(d)) Turbo((1.0 / d - lo) / range, &out.data[3 * i]);
  }
  return out;
}

void WriteRenderOutputs(const std::string& output_dir, const std::string& name,
                        const std::string& method, const Scene& scene,
                        const RenderResult& result, const RenderOutputOptions& options) {
  const std::string stem = output_dir + "/" + name;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(stem).parent_path(), ec);
  Require(!ec, std::filesystem::path(stem).parent_path().string(),
          "cannot create folder: " + ec.message());
  colmap::WriteImage(stem + ".png", result.color);
  if (options.write_depth) {
    colmap::WriteColmapArray(stem + ".depth.bin", result.depth);
    colmap::WriteImage(stem + ".depth.png", FalseColourDepth(result.depth));
  }
  if (options.write_confidence) {
    Image grey(result.confidence.width, result.confidence.height, 3);
    for (size_t i = 0; i < result.confidence.data.size(); ++i) {
      for (int c = 0; c < 3; ++c) grey.data[3 * i + c] = result.confidence.data[i];
    }
    colmap::WriteImage(stem + ".confidence.png", grey, 16);
  }
  if (options.write_infinity) {
    // A method that sets no mask: nothing was rendered from infinity.
    const Image mask = result.infinity.empty()
                           ? Image(result.color.width, result.color.height, 1)
                           : result.infinity;
    Image grey(mask.width, mask.height, 3);
    for (size_t i = 0; i < mask.data.size(); ++i) {
      for (int c = 0; c < 3; ++c) grey.data[3 * i + c] = mask.data[i] > 0 ? 1.f : 0.f;
    }
    colmap::WriteImage(stem + ".infinity.png", grey);
  }
  if (options.write_sources) {
    nlohmann::json json;
    json["target"] = name;
    json["method"] = method;
    json["sources"] = nlohmann::json::array();
    for (const SourceScore& s : result.sources) {
      const SceneView& view = scene.view(s.view_index);
      json["sources"].push_back({{"name", view.name},
                                 {"image_id", view.image_id},
                                 {"count", s.count},
                                 {"fraction", s.fraction}});
    }
    json["timings_s"] = {{"depth", result.timings.depth_s},
                         {"selection", result.timings.selection_s},
                         {"warp", result.timings.warp_s},
                         {"encode", result.timings.encode_s},
                         {"blend", result.timings.blend_s}};
    WriteFileAtomic(stem + ".sources.json",
                    [&](std::ostream& out) { out << json.dump(2) << "\n"; });
  }
}

}  // namespace fvs
