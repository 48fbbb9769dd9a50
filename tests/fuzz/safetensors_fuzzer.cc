// safetensors: network weights, packed training scenes (scene.safetensors) and stored
// source features all go through ParseSafeTensors. Beyond the container, what is read
// without LibTorch: every floating tensor converted to float (as weights are loaded) and
// the network config in the metadata (__metadata__["fvs_config"]).
#include "fuzz_support.h"
#include "fvs/net/model_config.h"
#include "fvs/util/safetensors.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace fvs::fuzz;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  fvs::SafeTensorsFile file;
  bool parsed = false;
  ExpectCleanResult([&] {
    file = fvs::ParseSafeTensors(bytes, "fuzz.safetensors");
    parsed = true;
  });
  if (!parsed) return 0;
  for (const fvs::SafeTensor& tensor : file.tensors) {
    ExpectCleanResult([&] { tensor.ToFloats(); });
  }
  const auto config = file.metadata.find("fvs_config");
  if (config != file.metadata.end()) {
    ExpectCleanResult([&] { fvs::ModelConfig::FromJson(config->second); });
  }
  // The file through the path reader too (its size checks are its own).
  const std::string path = WriteScratch("weights.safetensors", bytes);
  ExpectCleanResult([&] { fvs::ReadSafeTensors(path); });
  return 0;
}
