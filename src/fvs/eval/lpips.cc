#include "fvs/eval/lpips.h"

#include <torch/torch.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>

#include "fvs/net/image_tensor.h"
#include "fvs/net/lpips_net.h"
#include "fvs/net/net.h"
#include "fvs/util/error.h"

namespace fvs::eval {

PerceptualDistance LoadLpips(const std::string& path, std::string* why_not,
                             std::string* network) {
  why_not->clear();
  if (path.empty()) {
    *why_not = std::string("LPIPS: not available (no --lpips_path given, ") +
               kLpipsPathEnv + " not set)";
    return {};
  }
  try {
    Require(std::filesystem::is_regular_file(path), path, "no such file");
    ConfigureTorchThreads();
    std::shared_ptr<LpipsNetImpl> lpips = LpipsNet(path).ptr();
    lpips->eval();
    if (network) *network = lpips->network();
    auto mutex = std::make_shared<std::mutex>();
    return [lpips, mutex](const Image& a, const Image& b) {
      Require(a.channels == 3 && b.channels == 3, "LPIPS", "needs RGB images");
      std::lock_guard<std::mutex> lock(*mutex);
      torch::NoGradGuard no_grad;
      const double d = lpips->forward(ImageToTensor(a), ImageToTensor(b)).item<double>();
      Require(std::isfinite(d), "LPIPS", "distance is not finite");
      return d;
    };
  } catch (const std::exception& e) {
    *why_not = std::string("LPIPS: not available: ") + e.what();
    return {};
  }
}

}  // namespace fvs::eval
