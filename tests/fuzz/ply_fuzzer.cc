// PLY, ASCII and binary (both endians): read as a mesh (meshed-delaunay.ply) and as a
// point cloud (fused.ply), the two ways our stages read it.
#include "fuzz_support.h"
#include "fvs/geometry/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path =
      WriteScratch("model.ply", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] { fvs::ReadPlyMesh(path); });
  ExpectCleanResult([&] { fvs::ReadPlyPointCloud(path); });
  return 0;
}
