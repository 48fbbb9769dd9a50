// prepare's photo quality report (W/fvs/photo_quality.json, scene/photo_quality.h), which
// every scene load reads to rank blurry photos last: a broken file is one fvs::Error
// line, and a report that reads back gives a summary line.
#include "fuzz_support.h"
#include "fvs/scene/photo_quality.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path = WriteScratch(
      "photo_quality.json", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] {
    const fvs::PhotoQualityReport report = fvs::ReadPhotoQualityReport(path);
    report.Summary();
  });
  return 0;
}
