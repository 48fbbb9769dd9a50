// A COLMAP depth or normal map (.bin: "W&H&C&" then float32), as the stereo stage, the
// depth cache and the mesher read them.
#include "colmap_ext/dense_io.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path =
      WriteScratch("map.bin", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] { fvs::colmap::ReadColmapArray(path); });
  return 0;
}
