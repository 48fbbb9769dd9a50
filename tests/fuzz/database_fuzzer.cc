// COLMAP's database.db (sqlite), read by view_synthesis_prepare through our own queries.
#include "colmap_ext/database.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string path =
      WriteScratch("database.db", std::string(reinterpret_cast<const char*>(data), size));
  ExpectCleanResult([&] { fvs::colmap::ReadDatabase(path); });
  return 0;
}
