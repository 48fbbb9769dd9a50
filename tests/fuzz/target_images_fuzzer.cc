// images.txt targets (view_synthesis --target_images): the input is images.txt and,
// after kSeparator, the cameras.txt beside it (absent when there is no separator, so
// the workspace's cameras are looked up instead).
#include <Eigen/Core>

#include "fuzz_support.h"
#include "fvs/render/targets.h"
#include "fvs/scene/scene.h"

namespace {

// The workspace the targets refer to: one 8x6 view of camera 1 and a triangle.
const fvs::Scene& SmallScene() {
  static const fvs::Scene scene = [] {
    fvs::SceneView view;
    view.name = "view.png";
    view.image_id = 1;
    view.camera_id = 1;
    view.camera.width = 8;
    view.camera.height = 6;
    view.camera.fx = view.camera.fy = 8;
    view.camera.cx = 4;
    view.camera.cy = 3;
    fvs::TriangleMesh mesh;
    mesh.vertices = {{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}};
    mesh.faces = {{0, 1, 2}};
    return fvs::Scene::FromWorld({view}, mesh, 1);
  }();
  return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const fvs::Scene& scene = SmallScene();
  const std::vector<std::string> parts = SplitInput(data, size, 2);
  const std::string path = WriteScratch("images.txt", parts[0]);
  const std::string input(reinterpret_cast<const char*>(data), size);
  if (input.find(kSeparator) != std::string::npos) {
    WriteScratch("cameras.txt", parts[1]);
  } else {
    std::filesystem::remove(ScratchDir() + "/cameras.txt");
  }
  ExpectCleanResult([&] { fvs::ReadTargetImagesTxt(path, scene); });
  return 0;
}
