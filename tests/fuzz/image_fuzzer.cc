// Image files through OpenImageIO as we call it (photos, ground truth, finished frames).
// The first byte picks the file extension (OpenImageIO chooses its reader by it, then
// by the content), the rest is the file.
#include "colmap_ext/image_io.h"
#include "fuzz_support.h"

// OpenImageIO 2.4 leaks on the error path of its PNG reader (tests/lsan.supp): not our
// code. Its frames lack frame pointers, so LeakSanitizer needs the slow unwinder to see
// that the leak is in libOpenImageIO (here only: it slows every allocation).
extern "C" const char* __lsan_default_suppressions() { return "leak:libOpenImageIO\n"; }
extern "C" const char* __asan_default_options() { return "fast_unwind_on_malloc=0"; }

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
