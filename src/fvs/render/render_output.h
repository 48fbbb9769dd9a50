// Files `colmap view_synthesis` writes per target into the output folder O:
//   O/<name>.png              the rendered image (8-bit RGB)
//   O/<name>.depth.bin        target depth, COLMAP array format (float32, 0 = no surface)
//   O/<name>.depth.png        the same in false colour (near = warm), black = no surface
//   O/<name>.confidence.png   per-pixel confidence in [0, 1] as grey
//   O/<name>.infinity.png     white where the pixel was rendered from the background at
//                             infinity (no surface, some source sees it), else black
//   O/<name>.sources.json     which sources were used, with their scores and the timings
// All written atomically.
#pragma once

#include <string>

#include "fvs/render/method.h"

namespace fvs {

class Scene;

struct RenderOutputOptions {
  bool write_depth = false;
  bool write_confidence = false;
  bool write_infinity = false;
  bool write_sources = false;
};

void WriteRenderOutputs(const std::string& output_dir, const std::string& name,
                        const std::string& method, const Scene& scene,
                        const RenderResult& result, const RenderOutputOptions& options);

// Depth -> RGB false colour between the 2nd and 98th percentile of the surface depths
// (inverse depth, so near detail is visible). Black where there is no surface.
Image FalseColourDepth(const Image& depth);

}  // namespace fvs
