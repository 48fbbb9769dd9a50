// The workspace manifest (W/fvs/manifest.json) that lets view_synthesis_prepare skip
// finished stages. A corrupt one is not an error (a warning, stages run again), so here
// any fvs::Error is as much a finding as a crash: Load must not throw.
#include "fuzz_support.h"
#include "fvs/util/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path = WriteScratch(
      "manifest.json", std::string(reinterpret_cast<const char*>(data), size));
  const fvs::Manifest manifest = fvs::Manifest::Load(path, ScratchDir());
  // Looks up recorded stages and resolves their outputs (relative to the root).
  for (const char* stage : {"features", "matches", "sparse", "undistort", "stereo",
                            "fusion", "mesh", "depth_cache"}) {
    manifest.IsUpToDate(stage, "fingerprint", {path});
  }
  return 0;
}
