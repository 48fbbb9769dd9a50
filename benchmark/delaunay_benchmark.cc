// Delaunay graph-cut mesher: time per stage and accuracy against the true surface on a
// synthetic room with objects (1 M fused points, 50 cameras by default), plus the
// machine.
//
//   delaunay_benchmark [--points N] [--cameras K] [--noise S] [--outliers F]
//                      [--max_proj_dist PX] [--threads T]
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include "benchmark/benchmark_args.h"
#include "fvs/mvs/delaunay.h"
#include "fvs/util/machine.h"
#ifdef FVS_HAVE_CGAL
#include "fvs/mvs/delaunay_scene.h"
#endif
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace {

// The machine's load: on a shared machine wall times grow with it, CPU times much less.
std::string LoadAverage() {
  std::ifstream file("/proc/loadavg");
  std::string one, five;
  file >> one >> five;
  return one + " (1 min), " + five + " (5 min)";
}

}  // namespace

int main(int argc, char** argv) {
  fvs::benchmark::CheckArgs(
      argc, argv,
      "usage: delaunay_benchmark [--points N] [--cameras K] [--noise S] [--outliers F] "
      "[--max_proj_dist PX] [--threads T]",
      {"--cameras", "--max_proj_dist", "--noise", "--outliers", "--points", "--threads"});
#ifndef FVS_HAVE_CGAL
  std::fprintf(stderr,
               "built without CGAL or Boost.Graph: no Delaunay mesher to benchmark\n");
  return 1;
#else
  size_t num_points = 1000000;
  int num_cameras = 50;
  double noise = 0.01;
  double outliers = 0.05;
  fvs::mvs::DelaunayMeshingOptions options;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    const char* value = argv[i + 1];
    if (key == "--points")
      num_points = std::strtoull(value, nullptr, 10);
    else if (key == "--cameras")
      num_cameras = std::atoi(value);
    else if (key == "--noise")
      noise = std::atof(value);
    else if (key == "--outliers")
      outliers = std::atof(value);
    else if (key == "--max_proj_dist")
      options.max_proj_dist = std::atof(value);
    else if (key == "--threads")
      options.num_threads = std::atoi(value);
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 1;
    }
  }
  try {
    std::printf("machine: %u hardware threads, CPU %s, load average %s\n",
                std::thread::hardware_concurrency(), fvs::CpuModelName().c_str(),
                LoadAverage().c_str());
    fvs::Timer timer;
    const auto scene = fvs::mvs::MakeRoomScene(num_cameras, 640, 480);
    const auto cloud = fvs::mvs::SampleScene(scene, num_points, noise, outliers, 42);
    size_t views = 0;
    for (const auto& v : cloud.input.visibility) views += v.size();
    std::printf(
        "scene: room 10x6x3 m with 2 boxes and a sphere, %d cameras 640x480, %zu "
        "surface points (noise %.3f m) + %zu outliers, %.1f views per point "
        "(generated in %.1f s)\n",
        num_cameras, cloud.true_points.size(), noise, cloud.num_outliers,
        static_cast<double>(views) / cloud.input.points.size(), timer.Seconds());
    std::printf(
        "options: max_proj_dist %.1f px, max_depth_dist %.2f, visibility_sigma %.1f, "
        "distance_sigma_factor %.1f, quality_regularization %.1f, threads %d\n",
        options.max_proj_dist, options.max_depth_dist, options.visibility_sigma,
        options.distance_sigma_factor, options.quality_regularization,
        options.num_threads);
    fvs::mvs::DelaunayMeshingStats stats;
    const double cpu_before = fvs::ProcessCpuSeconds();
    const auto mesh = fvs::mvs::DelaunayMeshing(cloud.input, options, &stats);
    const double cpu_seconds = fvs::ProcessCpuSeconds() - cpu_before;
    std::printf("mesher: %s\n", stats.Summary().c_str());
    std::printf("mesher CPU time %.1f s (user + system, all threads); load average %s\n",
                cpu_seconds, LoadAverage().c_str());
    timer.Restart();
    const auto acc = fvs::mvs::EvaluateMesh(scene, mesh, cloud.true_points, 5 * noise);
    std::printf(
        "accuracy (m): vertices->true surface mean %.4f p90 %.4f; face samples mean "
        "%.4f p90 %.4f; coverage of the true surface within %.3f: %.1f%% "
        "(evaluated in %.1f s)\n",
        acc.vertex_mean, acc.vertex_p90, acc.face_mean, acc.face_p90, 5 * noise,
        100 * acc.coverage, timer.Seconds());
    std::printf(
        "RESULT delaunay_mesher points=%zu time_s=%.2f mean_dist=%.4f coverage=%.3f\n",
        cloud.input.points.size(), stats.seconds_total, acc.face_mean, acc.coverage);
  } catch (const fvs::Error& e) {
    std::fprintf(stderr, "ERROR: %s\n", e.what());
    return 1;
  }
  return 0;
#endif
}
