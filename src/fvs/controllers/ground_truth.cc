#include "fvs/controllers/ground_truth.h"

#include <filesystem>

#include "colmap_ext/image_io.h"
#include "fvs/eval/metrics.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace {

void RequireGroundTruthSize(const std::string& path, int truth_width, int truth_height,
                            int width, int height) {
  Require(truth_width == width && truth_height == height, path,
          "ground truth of " + std::to_string(truth_width) + "x" +
              std::to_string(truth_height) + " for a frame of " + std::to_string(width) +
              "x" + std::to_string(height));
}

}  // namespace

std::string GroundTruthFile(const std::string& dir, const std::string& name) {
  if (dir.empty()) return "";
  for (const char* ext : {".png", ".jpg", ".JPG", ".jpeg"}) {
    const std::string path = JoinPaths(dir, name + ext);
    if (std::filesystem::exists(path)) return path;
  }
  return "";
}

void CheckGroundTruth(const std::string& dir, const std::string& name,
                      const PinholeCamera& camera) {
  const std::string path = GroundTruthFile(dir, name);
  if (path.empty()) return;
  int width = 0, height = 0;
  colmap::ReadImageSize(path, &width, &height);
  RequireGroundTruthSize(path, width, height, camera.width, camera.height);
}

double FramePsnr(const std::string& dir, const std::string& name, const Image& color) {
  const std::string path = GroundTruthFile(dir, name);
  if (path.empty()) return -1;
  const Image truth = colmap::ReadImage(path);
  RequireGroundTruthSize(path, truth.width, truth.height, color.width, color.height);
  return eval::Psnr(color, truth);
}

}  // namespace fvs
