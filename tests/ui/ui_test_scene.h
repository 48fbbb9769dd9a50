// The generated scenes the application's tests open: 8 views of the synthetic room with
// its exact proxy mesh and 500 sparse points, written as a workspace into `path`.
#pragma once

#include <string>

#include "fvs/synthetic/generate.h"

namespace fvs::ui {

inline void GenerateUiTestScene(const std::string& path, int seed, int width,
                                int height) {
  SyntheticSceneOptions options;
  options.seed = seed;
  options.num_views = 8;
  options.width = width;
  options.height = height;
  options.num_sparse_points = 500;
  options.write_proxy_mesh = true;
  GenerateSyntheticScene(options, path);
}

}  // namespace fvs::ui
