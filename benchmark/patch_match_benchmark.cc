// Seconds per image of the CPU PatchMatch stereo stage (photometric + geometric + filter)
// on a generated scene with exact depth, printed with its accuracy (fraction of textured
// pixels within 1% relative depth error, and the full error histogram) and the machine.
//
//   patch_match_benchmark [--views N] [--width W] [--height H] [--threads T]
//                         [--scene synthetic|analytic] [--keep DIR] [--reuse 1]
//                         [--window_radius R] [--window_step S] [--top_k K]
//                         [--iterations N] [--geom_iterations N] [--fine_iterations N]
//                         [--coarse_levels N] [--min_consistent N] [--sigma_color C]
//                         [--sources N]
//                         [--filter_angle DEGREES] [--fast_refinement 0|1]
// --reuse 1 with --keep DIR skips generating the scene when DIR already holds one.
// Defaults: 6 views of the synthetic room at 800x600 on 2 threads.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "benchmark/benchmark_args.h"
#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/mvs/patch_match_stereo.h"
#include "fvs/mvs/stereo_accuracy.h"
#include "fvs/mvs/stereo_test_scene.h"
#include "fvs/synthetic/generate.h"
#include "fvs/util/error.h"
#include "fvs/util/machine.h"
#include "fvs/util/progress.h"

namespace {

double LoadAverage() {
  double load[1] = {0};
  return getloadavg(load, 1) == 1 ? load[0] : -1;
}

}  // namespace

int main(int argc, char** argv) {
  fvs::benchmark::CheckArgs(
      argc, argv,
      "usage: patch_match_benchmark [--views N] [--width W] [--height H] [--threads T] "
      "[--scene synthetic|analytic] [--keep DIR] [--reuse 1] [--window_radius R] "
      "[--window_step S] [--top_k K] [--iterations N] [--geom_iterations N] "
      "[--fine_iterations N] [--coarse_levels N] [--min_consistent N] [--sigma_color C] "
      "[--sources N] [--filter_angle DEGREES] [--fast_refinement 0|1]",
      {"--coarse_levels", "--fast_refinement", "--filter_angle", "--fine_iterations",
       "--geom_iterations", "--height", "--iterations", "--keep", "--min_consistent",
       "--reuse", "--scene", "--sigma_color", "--sources", "--threads", "--top_k",
       "--views", "--width", "--window_radius", "--window_step"});
  int views = 6, width = 800, height = 600, threads = 2;
  std::string scene_kind = "synthetic", keep;
  bool reuse = false;
  fvs::mvs::PatchMatchStereoOptions options;
  fvs::mvs::PatchMatchOptions& pm = options.patch_match;
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
    else if (a == "--reuse")
      reuse = std::atoi(argv[i + 1]) != 0;
    else if (a == "--window_radius")
      pm.window_radius = std::atoi(argv[i + 1]);
    else if (a == "--window_step")
      pm.window_step = std::atoi(argv[i + 1]);
    else if (a == "--top_k")
      pm.top_k = std::atoi(argv[i + 1]);
    else if (a == "--iterations")
      pm.num_iterations = std::atoi(argv[i + 1]);
    else if (a == "--geom_iterations")
      pm.num_geometric_iterations = std::atoi(argv[i + 1]);
    else if (a == "--fine_iterations")
      pm.num_fine_iterations = std::atoi(argv[i + 1]);
    else if (a == "--coarse_levels")
      pm.num_coarse_levels = std::atoi(argv[i + 1]);
    else if (a == "--min_consistent")
      pm.filter_min_num_consistent = std::atoi(argv[i + 1]);
    else if (a == "--sigma_color")
      pm.sigma_color = std::atof(argv[i + 1]);
    else if (a == "--filter_angle")
      pm.filter_min_triangulation_angle = std::atof(argv[i + 1]);
    else if (a == "--fast_refinement")
      pm.fast_refinement = std::atoi(argv[i + 1]) != 0;
    else if (a == "--sources")
      options.max_num_sources = std::atoi(argv[i + 1]);
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
                std::thread::hardware_concurrency(), fvs::CpuModelName().c_str(),
                threads);
    std::printf("scene: %s, %d views, %dx%d, workspace %s\n", scene_kind.c_str(), views,
                width, height, dir.c_str());
    fvs::Timer gen_timer;
    if (reuse && fs::exists(dir + "/sparse")) {
      std::printf("reusing the scene in %s\n", dir.c_str());
    } else if (scene_kind == "synthetic") {
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
    options.patch_match.num_threads = threads;
    options.overwrite = true;
    const double load_before = LoadAverage();
    const double cpu_before = fvs::ProcessCpuSeconds();
    const fvs::mvs::PatchMatchStereoSummary summary =
        fvs::mvs::RunPatchMatchStereo(dir, options);
    const double cpu_seconds = fvs::ProcessCpuSeconds() - cpu_before;
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
        "RESULT: %.2f s wall, %.2f s CPU per %dx%d image on %d threads (%d images, "
        "%.1f s wall total, load average %.1f before, %.1f after); textured pixels "
        "within 1%%: photometric %.4f, geometric %.4f (without depth: %.4f)\n",
        summary.seconds / computed, cpu_seconds / computed, width, height, threads,
        computed, summary.seconds, load_before, LoadAverage(),
        photometric.FractionWithin(0.01), geometric.FractionWithin(0.01),
        geometric.FractionWithoutDepth());
    if (keep.empty()) fs::remove_all(dir);
  } catch (const fvs::Error& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
}
