#include "ui/novel_view.h"

#include <cmath>

#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs::ui {

void NovelViewOptions::Check() const {
  Require(!method.empty(), "method", "no rendering method chosen");
  Require(num_sources >= 0, "K", "needs at least one source, or auto (0)");
  Require(width >= 8 && height >= 8 && width <= 8192 && height <= 8192, "resolution",
          "width and height must be between 8 and 8192 pixels");
}

RenderOptions NovelViewOptions::ToRenderOptions() const {
  RenderOptions options;
  options.num_sources = num_sources;
  options.max_num_sources = max_num_sources;
  options.selection_stride = selection_stride;
  options.model_path = model_path;
  options.feature_cache_dir = feature_cache_dir;
  options.scene_model_dir = scene_model_dir;
  return options;
}

PinholeCamera TargetCameraFor(const PinholeCamera& view, int width, int height) {
  PinholeCamera camera = view;
  const double fov_y = 2.0 * std::atan(0.5 * view.height / view.fy);
  camera.width = width;
  camera.height = height;
  camera.fy = 0.5 * height / std::tan(0.5 * fov_y);
  camera.fx = camera.fy * view.fx / view.fy;
  camera.cx = 0.5 * width;
  camera.cy = 0.5 * height;
  return camera;
}

RenderedView RenderNovelView(const Scene& scene, const PinholeCamera& scene_camera,
                             const NovelViewOptions& request) {
  request.Check();
  Require(scene_camera.IsValid(), "target camera", "the view's camera is not valid");
  const Timer timer;
  RenderedView view;
  view.method = request.method;
  view.num_sources = request.num_sources;
  view.camera = scene_camera;
  RenderOptions options = request.ToRenderOptions();
  options.Check();
  std::unique_ptr<Method> method = CreateMethod(request.method, options);
  TargetView target;
  target.name = "view";
  target.camera = scene_camera;
  view.result = method->Render(scene, target);
  view.seconds = timer.Seconds();
  if (!view.result.sources.empty()) {
    view.nearest_view = view.result.sources.front().view_index;
    view.nearest_photo = scene.SourceImage(view.nearest_view);
  }
  return view;
}

}  // namespace fvs::ui
