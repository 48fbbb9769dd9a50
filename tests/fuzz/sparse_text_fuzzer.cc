// COLMAP sparse model, text: the input is cameras.txt, images.txt and points3D.txt (cut
// at kSeparator).
#include "colmap_ext/sparse_io.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::vector<std::string> parts = SplitInput(data, size, 3);
  WriteScratch("cameras.txt", parts[0]);
  WriteScratch("images.txt", parts[1]);
  WriteScratch("points3D.txt", parts[2]);
  ExpectCleanResult([] { fvs::colmap::ReadSparseModelText(ScratchDir()); });
  return 0;
}
