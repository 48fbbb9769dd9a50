#include "fvs/scene/mesh_coverage.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "fvs/scene/scene.h"

namespace fvs {

double SurfaceFraction(const Image& depth) {
  const size_t pixels = static_cast<size_t>(depth.width) * depth.height;
  if (pixels == 0) return 0;
  size_t surface = 0;
  for (size_t i = 0; i < pixels; ++i) {
    const float d = depth.data[i * depth.channels];
    surface += d > 0 && std::isfinite(d);
  }
  return static_cast<double>(surface) / pixels;
}

MeshCoverage MeasureMeshCoverage(const Scene& scene) {
  MeshCoverage coverage;
  double sum = 0;
  for (int i = 0; i < scene.num_views(); ++i) {
    // The source depths hold the backdrop too: measure the mesh alone then.
    const double f = SurfaceFraction(scene.backdrop().faces.empty()
                                         ? scene.SourceDepth(i)
                                         : scene.RenderMeshDepth(scene.view(i).camera));
    coverage.names.push_back(scene.view(i).name);
    coverage.fractions.push_back(f);
    sum += f;
    if (coverage.least < 0 || f < coverage.fractions[coverage.least]) coverage.least = i;
  }
  if (scene.num_views() > 0) coverage.mean = sum / scene.num_views();
  return coverage;
}

std::string MeshCoverage::Summary() const {
  if (least < 0) return "mesh coverage: no views";
  char text[64];
  std::snprintf(text, sizeof(text), "%.1f%%", 100 * mean);
  std::string summary = std::string("mesh covers ") + text + " of the photos' pixels";
  std::snprintf(text, sizeof(text), "%.1f%%", 100 * fractions[least]);
  return summary + " (least: " + names[least] + ", " + text + ")";
}

std::string MeshCoverage::ToJson() const {
  nlohmann::json json;
  json["mean"] = mean;
  json["views"] = nlohmann::json::object();
  for (size_t i = 0; i < names.size(); ++i) json["views"][names[i]] = fractions[i];
  return json.dump(1);
}

}  // namespace fvs
