// colmap view_synthesis_model_info: parameters, FLOPs per source and the time of one K =
// 1 forward of every network variant (or of one, or of a weights file) at a given size.
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include "fvs/exe/command_registry.h"
#include "fvs/net/net.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/option_manager.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

int RunViewSynthesisModelInfo(int argc, char** argv) {
  std::string model = "all";
  std::string weights;
  int width = 480;
  int height = 270;
  bool time_forward = true;
  OptionManager options(
      "view_synthesis_model_info",
      "Parameter counts, FLOPs per source and CPU time of one forward of the "
      "view-synthesis networks.");
  options.AddDefault(
      "model", &model,
      "network variant (fvs, fvs_nogru, fvs_nomasks, fvs_noinfdepth, fvs_single, "
      "fvs_fast) or 'all'");
  options.AddDefault(
      "weights", &weights,
      "a .safetensors weights file: describe (and check) its network instead");
  options.AddDefault("width", &width, "target and source width in pixels");
  options.AddDefault("height", &height, "target and source height in pixels");
  options.AddDefault("time", &time_forward,
                     "time one forward with one source on the CPU");
  if (!options.Parse(argc, argv)) return 0;
  Require(width > 0 && height > 0, "view_synthesis_model_info",
          "--width and --height must be positive");

  ConfigureTorchThreads();
  std::cout << "machine: " << std::thread::hardware_concurrency() << " cores (nproc), "
            << CpuModelName() << ", LibTorch threads " << torch::get_num_threads()
            << "\n";

  std::vector<std::pair<ModelConfig, FvsNet>> nets;
  if (!weights.empty()) {
    ModelConfig config;
    FvsNet net = LoadModel(weights, &config);
    std::cout << "weights: " << weights << "\nconfig: " << config.ToJson() << "\n";
    nets.emplace_back(config, net);
  } else {
    const std::vector<std::string> names =
        model == "all" ? ModelConfig::KnownVariants() : std::vector<std::string>{model};
    for (const std::string& name : names) {
      const ModelConfig config = ModelConfig::ForVariant(name);
      torch::manual_seed(0);  // random weights: the cost does not depend on their values
      nets.emplace_back(config, FvsNet(config));
    }
  }
  for (auto& [config, net] : nets) {
    std::cout << FormatModelInfo(DescribeModel(net, width, height, time_forward))
              << std::flush;
  }
  return 0;
}

FVS_REGISTER_COMMAND("view_synthesis_model_info",
                     "parameters, FLOPs and CPU time of the view-synthesis networks",
                     RunViewSynthesisModelInfo);

}  // namespace
}  // namespace fvs
