// Image files through OpenImageIO as we call it (photos, ground truth, finished frames).
// The first byte picks the file extension (OpenImageIO chooses its reader by it, then
// by the content), the rest is the file.
#include "colmap_ext/image_io.h"
#include "fuzz_support.h"

// OpenImageIO 2.4 leaks on the error path of its PNG reader (tests/lsan.supp): not our
// code. Its frames lack frame pointers, so LeakSanitizer could tell that leak from ours
// only with the slow unwinder, which took this target from thousands of executions a
// minute to 51 in 30 s: leaks are not checked here (colmap_ext/image_io.cc holds the
// reader in a unique_ptr; the unit tests under FVS_SANITIZE check it for leaks).
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".png", ".jpg", ".tif", ".exr",
                                            ".bmp", ".ppm", ".hdr", ".tga"};
  const char* extension = kExtensions[data[0] % (sizeof(kExtensions) / sizeof(char*))];
  const std::string path =
      WriteScratch(std::string("image") + extension,
                   std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  ExpectCleanResult([&] { fvs::colmap::ReadImage(path, 3); });
  ExpectCleanResult([&] { fvs::colmap::ReadImage(path, 1); });
  ExpectCleanResult([&] {
    int width = 0, height = 0;
    fvs::colmap::ReadImageSize(path, &width, &height);
  });
  fvs::colmap::IsCompleteImage(path, 8, 6);  // never throws
  std::filesystem::remove(path);
  return 0;
}
