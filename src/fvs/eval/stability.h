// The renderer's numerical stability suite, runnable from one command
// (view_synthesis_stability): small generated scenes that push the geometry to its
// edges, each rendered at the origin and again with the whole world 10 km away, with
// every method asked for. Per case and method: NaN and Inf counts in the outputs (colour,
// confidence, depth), the maximum colour deviation between the two placements, and time.
// The cases (doc/design.md, "Numbers that matter"):
//   depth_0        a target that sees only sky (target depth 0 everywhere)
//   depth_1e30     a target that sees a backdrop 1e30 away
//   behind_sources a target whose every point is behind every source camera
//   edge_on        one source whose image plane contains the target's centre
//   single_source  a scene of one view
//   k_too_large    K = 64 in a scene of 6 views
// plus "reference", an ordinary view between two sources, as the yardstick.
#pragma once

#include <string>
#include <vector>

#include "fvs/render/method.h"

namespace fvs::eval {

struct StabilityOptions {
  std::vector<std::string> methods = {"nearest", "ulr"};
  std::string model_path;          // for network methods (random weights are fine here)
  std::string precision = "fp32";  // of network methods (RenderOptions::precision)
  int tile_size = 512;             // of network methods (RenderOptions::tile_size)
  int width = 64, height = 48;
  double far_offset_m = 10000.0;  // distance of the far copy from the origin
  int num_threads = 0;
};

struct StabilityResult {
  std::string case_name;
  std::string method;
  std::string error;                  // the render threw (that is a failure too)
  long nan_count = 0, inf_count = 0;  // over both placements and all outputs
  double covered = 0;                 // fraction of pixels with a contribution (origin)
  double max_deviation = 0;   // max |colour(origin) - colour(far)| over pixels, channels
  long pixels_deviating = 0;  // pixels with a channel differing by more than 1/255
  double seconds = 0;         // both renders
  bool ok() const {
    return error.empty() && nan_count == 0 && inf_count == 0 &&
           max_deviation <= 1.0 / 255;
  }
};

std::vector<std::string> StabilityCaseNames();
std::vector<StabilityResult> RunStabilitySuite(const StabilityOptions& options);

}  // namespace fvs::eval
