// A nerfstudio camera_path.json, read both ways: as render targets (view_synthesis
// --camera_path) and as keyframes (view_synthesis_path --keyframes_path).
#include "fuzz_support.h"
#include "fvs/path/camera_path.h"
#include "fvs/render/targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path = WriteScratch(
      "camera_path.json", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] { fvs::ReadNerfstudioCameraPath(path); });
  ExpectCleanResult([&] { fvs::ReadNerfstudioKeyframes(path); });
  return 0;
}
