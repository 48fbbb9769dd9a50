// How the blur rule of prepare's photo_quality stage (scene/photo_quality.h) reads real
// photo sets: per scene, how many photos it calls blurry (on curated sets, a false alarm
// demotes a good source), the lowest relative sharpness, near-duplicate pairs, and how
// far a known blur moves a typical photo (the scene's median-sharpness photo blurred by
// a 3x3 box once, twice and four times, at its stored size), beside the seconds.
//
//   photo_quality_benchmark --scenes ../shared/datasets/fox,../shared/datasets/monstree
//
// A scene is a dataset folder (images/ and sparse/0) or a prepared workspace (images/ and
// sparse/).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "colmap_ext/image_io.h"
#include "fvs/scene/photo_quality.h"
#include "fvs/util/error.h"
#include "fvs/util/image_resize.h"
#include "fvs/util/machine.h"
#include "fvs/util/string_util.h"

namespace fs = std::filesystem;
using namespace fvs;

namespace {

// A workspace view of a dataset folder: W/images and W/sparse as links.
std::string AsWorkspace(const std::string& scene, const std::string& tmp) {
  if (fs::exists(scene + "/sparse/cameras.bin") ||
      fs::exists(scene + "/sparse/cameras.txt")) {
    return scene;
  }
  const std::string w = tmp + "/" + fs::path(scene).filename().string();
  fs::create_directories(w);
  fs::create_symlink(fs::absolute(scene + "/images"), w + "/images");
  fs::create_symlink(fs::absolute(scene + "/sparse/0"), w + "/sparse");
  return w;
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage =
      "photo_quality_benchmark --scenes A,B,... (dataset folders or workspaces)";
  benchmark::CheckArgs(argc, argv, usage, {"--scenes"});
  std::string scenes;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::string(argv[i]) == "--scenes") scenes = argv[i + 1];
  }
  if (scenes.empty()) {
    std::fprintf(stderr, "ERROR: --scenes: needed\n%s\n", usage);
    return 2;
  }
  const std::string tmp =
      (fs::temp_directory_path() / ("photo_quality_" + std::to_string(::getpid())))
          .string();
  std::printf("machine: %s\n", DescribeMachine().c_str());
  std::printf(
      "| scene | photos | blurry | lowest relative | duplicate pairs | median photo "
      "blurred 3x3 x1 / x2 / x4 (relative) | s |\n| --- | --- | --- | --- | --- | "
      "--- | --- |\n");
  try {
    for (const std::string& scene : SplitString(scenes, ",")) {
      const std::string w = AsWorkspace(scene, tmp);
      const auto start = std::chrono::steady_clock::now();
      const PhotoQualityReport r = MeasurePhotoQuality(w, PhotoQualityOptions());
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const PhotoQuality* lowest = nullptr;
      const PhotoQuality* median = nullptr;
      int pairs = 0;
      for (const PhotoQuality& q : r.photos) {
        if (!lowest || q.relative < lowest->relative) lowest = &q;
        if (!median || std::abs(q.relative - 1) < std::abs(median->relative - 1))
          median = &q;
        pairs += static_cast<int>(q.duplicates.size());
      }
      std::string blurred;
      if (median) {
        Image image = colmap::ReadImage(JoinPaths(w + "/images", median->name));
        const double base = Sharpness(image) / median->relative;  // the median it met
        for (int passes = 1; passes <= 4; ++passes) {
          image = BoxBlur(image, 1);
          if (passes == 1 || passes == 2 || passes == 4) {
            char text[32];
            std::snprintf(text, sizeof(text), "%s%.2f", blurred.empty() ? "" : " / ",
                          Sharpness(image) / base);
            blurred += text;
          }
        }
      }
      std::printf("| %s | %zu | %d | %.2f (%s) | %d | %s | %.1f |\n",
                  fs::path(scene).filename().c_str(), r.photos.size(), r.num_blurry(),
                  lowest ? lowest->relative : 0.0, lowest ? lowest->name.c_str() : "-",
                  pairs / 2, blurred.c_str(), seconds);
      std::fflush(stdout);
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    fs::remove_all(tmp);
    return 1;
  }
  fs::remove_all(tmp);
  return 0;
}
