// Seconds per image of the CPU PatchMatch stereo stage (photometric + geometric + filter)
// on a generated scene with exact depth, printed with its accuracy (fraction of textured
// pixels within 1% relative depth error, and the full error histogram) and the machine.
//
//   patch_match_benchmark [--views N] [--width W] [--height H] [--threads T]
//                         [--scene synthetic|analytic] [--keep DIR]
// Defaults: 6 views of the synthetic room at 800x600 on 2 threads.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/mvs/patch_match_stereo.h"
#include "fvs/mvs/stereo_accuracy.h"
#include "fvs/mvs/stereo_test_scene.h"
#include "fvs/synthetic/generate.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace {

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown";
}

}  // namespace

int main(int argc, char** argv) {
  int views = 6, width = 800, height = 600, threads = 2;
  std::string scene_kind = "synthetic", keep;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--views")
      views = std::atoi(argv[i + 1]);
    else if (a == "--width")
      width = std::atoi(argv[i + 1]);
    else if (a == "--height")
      height = std::atoi(argv[i + 1]);
    else if (a == "--threads")
      threads = std::atoi(argv[i + 1]);
    else if (a == "--scene")
      scene_kind = argv[i + 1];
    else if (a == "--keep")
      keep = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  try {
    namespace fs = std::filesystem;
    const std::string dir =
        keep.empty()
            ? (fs::temp_directory_path() / ("fvs_pm_bench_" + std::to_string(getpid())))
                  .string()
            : keep;
    std::printf("machine: nproc %u, %s; stereo threads %d\n",
                std::thread::hardware_concurrency(), CpuModel().c_str(), threads);
    std::printf("scene: %s, %d views, %dx%d, workspace %s\n", scene_kind.c_str(), views,
                width, height, dir.c_str());
    fvs::Timer gen_timer;
    if (scene_kind == "synthetic") {
      fvs::SyntheticSceneOptions options;
      options.num_views = views;
      options.width = width;
      options.height = height;
      options.seed = 3;
      fvs::GenerateSyntheticScene(options, dir);
    } else {
      fvs::mvs::AnalyticSceneOptions options;
      options.num_views = views;
      options.width = width;
      options.height = height;
      fvs::mvs::WriteAnalyticWorkspace(fvs::mvs::RenderAnalyticScene(options), dir);
    }
    std::printf("scene generated in %.1f s\n", gen_timer.Seconds());
    const fvs::colmap::DenseWorkspace ws(dir);
    fvs::mvs::PatchMatchStereoOptions options;
    options.patch_match.num_threads = threads;
    options.overwrite = true;
    const fvs::mvs::PatchMatchStereoSummary summary =
        fvs::mvs::RunPatchMatchStereo(dir, options);
    const int computed = std::max(1, summary.num_photometric_computed);

    const fvs::colmap::Reconstruction rec = fvs::colmap::ReadSparseModel(ws.SparseDir());
    fvs::mvs::DepthErrorHistogram photometric, geometric;
    for (const auto& [id, image] : rec.images) {
      const std::string gt_path = scene_kind == "synthetic"
                                      ? fvs::SyntheticDepthMapPath(dir, image.name)
                                      : dir + "/ground_truth/" + image.name + ".bin";
      const fvs::Image gt = fvs::colmap::ReadColmapArray(gt_path);
      const std::vector<uint8_t> textured =
          fvs::mvs::TexturedMask(fvs::colmap::ReadImage(ws.ImagePath(image.name), 1));
      photometric.Add(
          fvs::colmap::ReadColmapArray(ws.DepthMapPath(image.name, "photometric")), gt,
          textured);
      geometric.Add(
          fvs::colmap::ReadColmapArray(ws.DepthMapPath(image.name, "geometric")), gt,
          textured);
    }
    std::printf(
        "%s", photometric.ToString("photometric (unfiltered), textured pixels").c_str());
    std::printf("%s",
                geometric.ToString("geometric (filtered), textured pixels").c_str());
    std::printf(
        "RESULT: %.2f s per %dx%d image on %d threads (%d images, %.1f s total); "
        "textured "
        "pixels within 1%%: photometric %.4f, geometric %.4f\n",
        summary.seconds / computed, width, height, threads, computed, summary.seconds,
        photometric.FractionWithin(0.01), geometric.FractionWithin(0.01));
    if (keep.empty()) fs::remove_all(dir);
  } catch (const fvs::Error& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
}
