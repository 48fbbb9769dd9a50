// Helpers shared by the render tests (beside scene/scene_fixture.h, which the scene
// tests use without the render library).
#pragma once

#include "fvs/render/method.h"
#include "fvs/scene/scene.h"

namespace fvs::testing {

// View `view` of the scene as a target that does not use its own photo.
inline TargetView HeldOutTarget(const Scene& scene, int view) {
  TargetView target;
  target.name = "target";
  target.camera = scene.view(view).camera;
  target.exclude_views = {view};
  return target;
}

}  // namespace fvs::testing
