// COLMAP sparse model, binary: the input is cameras.bin, images.bin and points3D.bin
// (cut at kSeparator), read as `colmap view_synthesis` reads W/sparse.
#include "colmap_ext/sparse_io.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::vector<std::string> parts = SplitInput(data, size, 3);
  WriteScratch("cameras.bin", parts[0]);
  WriteScratch("images.bin", parts[1]);
  WriteScratch("points3D.bin", parts[2]);
  ExpectCleanResult([] { fvs::colmap::ReadSparseModelBinary(ScratchDir()); });
  return 0;
}
