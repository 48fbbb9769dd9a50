// One novel view rendered for the window: the request (method, K, size, weights) and what
// the result panel shows (the render, the nearest source photo, the time it took). No Qt
// here, so the rendering path of the GUI is the command line's: fvs::CreateMethod and
// Method::Render on the prepared scene.
#pragma once

#include <string>

#include "fvs/render/method.h"
#include "fvs/scene/scene.h"

namespace fvs::ui {

struct NovelViewOptions {
  std::string method = "ulr";
  int num_sources = 0;  // 0 = auto (RenderOptions::num_sources)
  int max_num_sources = RenderOptions().max_num_sources;  // of auto
  int selection_stride = 1;  // RenderOptions::selection_stride (the live frames: 2)
  int width = 640;
  int height = 480;
  std::string model_path;  // weights, for the fvs methods
  // Encoded source features kept here for the next render (the window's workspace's
  // fvs/features): each render creates its method afresh, so without it every click
  // would encode every source again. Empty = none.
  std::string feature_cache_dir;
  std::string scene_model_dir;  // a scene's fine-tuned weights (RenderOptions)
  // Throws fvs::Error naming the setting that is out of range.
  void Check() const;
  RenderOptions ToRenderOptions() const;
};

struct RenderedView {
  std::string method;
  int num_sources = 0;   // K asked for
  PinholeCamera camera;  // scene frame
  RenderResult result;
  int nearest_view = -1;  // scene view index of the best source, -1 if none
  Image nearest_photo;    // its photo (empty if none)
  double seconds = 0;     // wall time of method creation + render
};

// The target camera for a viewer pose: the pose and vertical field of view of `view`
// at the requested size.
PinholeCamera TargetCameraFor(const PinholeCamera& view, int width, int height);

// Creates the method and renders one view. Throws fvs::Error (no weights, a bad setting,
// a failed render) with one line naming what is wrong.
RenderedView RenderNovelView(const Scene& scene, const PinholeCamera& scene_camera,
                             const NovelViewOptions& request);

}  // namespace fvs::ui
