// Rasteriser benchmark: a ~1 M-triangle scene (a height-field terrain inside a room, with
// two spheres) rendered at 960x540 from several cameras. Prints, per run of the program,
// the time per depth view (median), the time with colours and face ids, and the accuracy
// against the ray-cast reference (max / mean relative depth error, fraction of pixels
// whose coverage differs) beside the machine. Also times PLY writing and reading of the
// same mesh.
//
// Usage: rasterizer_benchmark [--views N] [--runs R] [--check_rows K] [--threads T]
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "benchmark/benchmark_args.h"
#include "fvs/geometry/look_at.h"
#include "fvs/geometry/ply.h"
#include "fvs/geometry/rasterizer.h"
#include "fvs/util/machine.h"
#include "fvs/util/parallel.h"
#include "fvs/util/progress.h"

namespace {

using fvs::PinholeCamera;
using fvs::TriangleMesh;

void Append(TriangleMesh* mesh, const TriangleMesh& part) {
  const int base = static_cast<int>(mesh->vertices.size());
  mesh->vertices.insert(mesh->vertices.end(), part.vertices.begin(), part.vertices.end());
  mesh->colors.insert(mesh->colors.end(), part.colors.begin(), part.colors.end());
  for (const auto& f : part.faces)
    mesh->faces.push_back(f + Eigen::Vector3i::Constant(base));
}

// Rolling terrain over [-10, 10]^2 (z up), n x n quads.
TriangleMesh Terrain(int n) {
  TriangleMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -10 + 20.0 * i / n, y = -10 + 20.0 * j / n;
      const double z =
          0.6 * std::sin(0.9 * x) * std::cos(0.7 * y) + 0.15 * std::sin(3.1 * x + 2 * y);
      mesh.vertices.emplace_back(x, y, z);
      mesh.colors.emplace_back(static_cast<uint8_t>(128 + 100 * std::sin(x)),
                               static_cast<uint8_t>(128 + 100 * std::cos(y)),
                               static_cast<uint8_t>(128 + 60 * z));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      mesh.faces.emplace_back(a, b, c);
      mesh.faces.emplace_back(a, c, d);
    }
  }
  return mesh;
}

TriangleMesh Sphere(int subdivisions, double radius, const Eigen::Vector3d& center) {
  // UV sphere: simple and closed enough for a benchmark (poles are fans).
  const int rings = subdivisions, segments = 2 * subdivisions;
  TriangleMesh mesh;
  for (int r = 0; r <= rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      const Eigen::Vector3d d(std::sin(theta) * std::cos(phi),
                              std::sin(theta) * std::sin(phi), std::cos(theta));
      mesh.vertices.push_back(center + radius * d);
      mesh.colors.emplace_back(200, static_cast<uint8_t>(100 + 100 * d.z()), 50);
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s, b = r * segments + (s + 1) % segments;
      const int c = b + segments, d = a + segments;
      mesh.faces.emplace_back(a, d, c);
      mesh.faces.emplace_back(a, c, b);
    }
  }
  return mesh;
}

TriangleMesh Room(double half, double height, int n) {
  TriangleMesh mesh;
  const Eigen::Vector3d lo(-half, -half, -1), hi(half, half, height);
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      const int base = static_cast<int>(mesh.vertices.size());
      for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
          Eigen::Vector3d p;
          p[axis] = side ? hi[axis] : lo[axis];
          p[u] = lo[u] + (hi[u] - lo[u]) * i / n;
          p[w] = lo[w] + (hi[w] - lo[w]) * j / n;
          mesh.vertices.push_back(p);
          mesh.colors.emplace_back(90, 90, static_cast<uint8_t>(60 * axis + 30 * side));
        }
      }
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const int a = base + j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
          mesh.faces.emplace_back(a, b, c);
          mesh.faces.emplace_back(a, c, d);
        }
      }
    }
  }
  return mesh;
}

PinholeCamera LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  return fvs::LookAtCamera(eye, target, 960, 540, 700);
}

double LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = 0;
  in >> load;
  return load;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  fvs::benchmark::CheckArgs(
      argc, argv,
      "usage: rasterizer_benchmark [--views N] [--runs R] [--check_rows K] [--threads T]",
      {"--check_rows", "--runs", "--threads", "--views"});
  int views = 8, runs = 5, check_rows = 60, threads = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string arg = argv[i];
    const int value = std::atoi(argv[i + 1]);
    if (arg == "--views") views = std::max(1, value);
    if (arg == "--runs") runs = std::max(1, value);
    if (arg == "--check_rows") check_rows = std::max(0, value);
    if (arg == "--threads") threads = value;
  }
  TriangleMesh mesh;
  Append(&mesh, Terrain(640));                    // 819200 faces
  Append(&mesh, Sphere(200, 1.5, {2, 1, 1.5}));   // 160000 faces
  Append(&mesh, Sphere(60, 0.8, {-3, -2, 1.2}));  // 14400 faces
  Append(&mesh, Room(12, 6, 24));                 // 6912 faces
  const int num_threads = threads > 0 ? threads : fvs::DefaultNumThreads();
  std::printf("machine: nproc %ld, CPU %s, threads used %d\n",
              sysconf(_SC_NPROCESSORS_ONLN), fvs::CpuModelName().c_str(), num_threads);
  std::printf("mesh: %zu vertices, %zu faces; image 960x540\n", mesh.vertices.size(),
              mesh.faces.size());

  std::vector<PinholeCamera> cameras;
  for (int v = 0; v < views; ++v) {
    const double a = 2 * M_PI * v / views;
    const Eigen::Vector3d eye(7 * std::cos(a), 7 * std::sin(a),
                              2.5 + 1.5 * std::sin(3 * a));
    cameras.push_back(LookAt(eye, Eigen::Vector3d(0.5 * std::sin(a), 0, 0.3)));
  }

  fvs::RasterizeOptions depth_only;
  depth_only.num_threads = num_threads;
  fvs::RasterizeOptions full = depth_only;
  full.compute_color = true;
  full.compute_face_ids = true;
  std::vector<double> depth_times, full_times, depth_cpu;
  std::vector<fvs::Image> depths;
  for (const PinholeCamera& camera : cameras) {
    for (int r = 0; r < runs; ++r) {
      const double cpu0 = fvs::ProcessCpuSeconds();
      fvs::Timer timer;
      fvs::RasterResult result = fvs::Rasterize(mesh, camera, depth_only);
      depth_times.push_back(timer.Seconds());
      depth_cpu.push_back(fvs::ProcessCpuSeconds() - cpu0);
      if (r == 0) depths.push_back(std::move(result.depth));
    }
    fvs::Timer timer;
    fvs::Rasterize(mesh, camera, full);
    full_times.push_back(timer.Seconds());
  }

  // Accuracy against the ray cast, on a band of rows of each view (the BVH reference
  // costs seconds per view).
  double max_rel = 0, sum_rel = 0;
  int64_t both = 0, differ = 0, checked = 0;
  double raycast_seconds = 0;
  std::vector<double> worst(5, 0);  // view, x, y, raster depth, ray-cast depth
  if (check_rows > 0) {
    for (size_t v = 0; v < cameras.size(); ++v) {
      const int y0 = static_cast<int>((v * 97) % (540 - check_rows));
      fvs::Timer timer;
      const fvs::Image reference =
          fvs::RayCastDepth(mesh, cameras[v], y0, y0 + check_rows);
      raycast_seconds += timer.Seconds();
      for (int y = y0; y < y0 + check_rows; ++y) {
        for (int x = 0; x < 960; ++x) {
          const float a = depths[v].at(x, y), b = reference.at(x, y);
          ++checked;
          if ((a > 0) != (b > 0)) {
            ++differ;
          } else if (a > 0) {
            const double rel = std::abs(a - b) / b;
            if (rel > max_rel) {
              max_rel = rel;
              worst = {static_cast<double>(v), static_cast<double>(x),
                       static_cast<double>(y), a, b};
            }
            sum_rel += rel;
            ++both;
          }
        }
      }
    }
  }

  // PLY round trip of the same mesh (binary, float coordinates as COLMAP writes).
  const std::string ply_path =
      "/tmp/fvs_rasterizer_benchmark_" + std::to_string(getpid()) + ".ply";
  double cpu = fvs::ProcessCpuSeconds();
  fvs::Timer timer;
  fvs::WritePlyMesh(ply_path, mesh);
  const double write_seconds = timer.Seconds();
  const double write_cpu = fvs::ProcessCpuSeconds() - cpu;
  cpu = fvs::ProcessCpuSeconds();
  timer.Restart();
  const TriangleMesh back = fvs::ReadPlyMesh(ply_path);
  const double read_seconds = timer.Seconds();
  const double read_cpu = fvs::ProcessCpuSeconds() - cpu;
  std::remove(ply_path.c_str());

  std::printf(
      "depth only: wall median %.2f ms per view (min %.2f, %d views x %d runs); CPU "
      "median %.2f ms per view summed over threads (CPU / threads = %.2f ms); load "
      "average "
      "%.1f\n",
      1e3 * Median(depth_times),
      1e3 * *std::min_element(depth_times.begin(), depth_times.end()), views, runs,
      1e3 * Median(depth_cpu), 1e3 * Median(depth_cpu) / num_threads, LoadAverage());
  std::printf("depth + colour + face ids: median %.2f ms per view\n",
              1e3 * Median(full_times));
  if (check_rows > 0) {
    std::printf(
        "accuracy vs ray cast (%lld pixels, %d rows per view): max rel depth error %.3g, "
        "mean "
        "%.3g, coverage differs at %.4f%% of pixels (%lld); ray cast took %.1f s\n",
        static_cast<long long>(checked), check_rows, max_rel, both ? sum_rel / both : 0.0,
        100.0 * differ / std::max<int64_t>(checked, 1), static_cast<long long>(differ),
        raycast_seconds);
    std::printf("worst pixel: view %g (%g, %g): raster %.7g, ray cast %.7g\n", worst[0],
                worst[1], worst[2], worst[3], worst[4]);
  }
  std::printf(
      "PLY binary %zu faces: write %.0f ms (CPU %.0f ms), read %.0f ms (CPU %.0f ms) "
      "(%s)\n",
      back.faces.size(), 1e3 * write_seconds, 1e3 * write_cpu, 1e3 * read_seconds,
      1e3 * read_cpu, back.faces == mesh.faces ? "faces identical" : "FACES DIFFER");
  return 0;
}
