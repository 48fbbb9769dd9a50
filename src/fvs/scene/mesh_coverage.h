// How much of what the photos show the proxy mesh covers: for each registered view, the
// fraction of its pixels where the mesh rendered into that view has a surface (the source
// depth cache; 0 = no surface; the mesh alone when the scene has a backdrop). Pixels without a surface are rendered from the background
// at infinity, or filled, so a low fraction where the photo shows near things means the
// geometry lost them (doc/real_scenes.md).
#pragma once

#include <string>
#include <vector>

#include "fvs/util/image.h"

namespace fvs {

class Scene;

struct MeshCoverage {
  std::vector<std::string> names;  // one per view, Scene order
  std::vector<double> fractions;   // in [0, 1], same order
  double mean = 0;                 // over the views; 0 when there are none
  int least = -1;                  // index of the least covered view, -1 when none

  // "mesh covers 63.2% of the photos' pixels (least: IMG_12.jpg, 12.5%)".
  std::string Summary() const;
  std::string ToJson() const;  // {"mean":..,"views":{"name":fraction,..}}
};

// The fraction of pixels of a depth image with a surface (> 0 and finite).
double SurfaceFraction(const Image& depth);

MeshCoverage MeasureMeshCoverage(const Scene& scene);

}  // namespace fvs
