// stereo/patch-match.cfg, read by view_synthesis_stereo against the sparse model: here a
// small model of three images (a.png, b.png, c.png) sharing two 3D points.
#include "colmap_ext/reconstruction.h"
#include "fuzz_support.h"
#include "fvs/mvs/stereo_config.h"

namespace {

const fvs::colmap::Reconstruction& SmallModel() {
  static const fvs::colmap::Reconstruction model = [] {
    fvs::colmap::Reconstruction r;
    fvs::colmap::Camera camera;
    camera.camera_id = 1;
    camera.model_id = 1;  // PINHOLE
    camera.width = 8;
    camera.height = 6;
    camera.params = {8, 8, 4, 3};
    r.cameras[1] = camera;
    const char* const names[] = {"a.png", "b.png", "c.png"};
    for (uint32_t id = 1; id <= 3; ++id) {
      fvs::colmap::Image image;
      image.image_id = id;
      image.camera_id = 1;
      image.name = names[id - 1];
      image.tvec = Eigen::Vector3d(0.5 * id, 0, 0);
      image.points2D.resize(2);
      r.images[id] = image;
    }
    for (uint64_t p = 0; p < 2; ++p) {
      fvs::colmap::Point3D point;
      point.xyz = Eigen::Vector3d(0.1 * p, 0, 4);
      for (uint32_t id = 1; id <= 3; ++id) {
        r.images[id].points2D[p].point3D_id = p;
        point.track.push_back({id, static_cast<uint32_t>(p)});
      }
      r.points3D[p] = point;
    }
    return r;
  }();
  return model;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path = WriteScratch(
      "patch-match.cfg", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] { fvs::mvs::ReadPatchMatchConfig(path, SmallModel(), 1.0); });
  return 0;
}
