// fused.ply.vis (per fused point, the images that see it), as the mesher reads it.
#include "colmap_ext/dense_io.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path = WriteScratch(
      "fused.ply.vis", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] { fvs::colmap::ReadFusedVisibility(path); });
  return 0;
}
