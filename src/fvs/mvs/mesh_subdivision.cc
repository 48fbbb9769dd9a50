#include "fvs/mvs/mesh_subdivision.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

#include "fvs/util/parallel.h"

namespace fvs::mvs {
namespace {

uint64_t EdgeKey(int a, int b) {
  const uint64_t lo = static_cast<uint32_t>(std::min(a, b));
  const uint64_t hi = static_cast<uint32_t>(std::max(a, b));
  return hi << 32 | lo;
}

// The faces of `f` once the edges with a midpoint in `mid` (-1: not split) are split;
// edge k runs from f[k] to f[k + 1].
void SplitFace(const Eigen::Vector3i& f, const int mid[3],
               std::vector<Eigen::Vector3i>* faces) {
  const int num_split = (mid[0] >= 0) + (mid[1] >= 0) + (mid[2] >= 0);
  if (num_split == 0) {
    faces->push_back(f);
  } else if (num_split == 3) {
    faces->push_back({f[0], mid[0], mid[2]});
    faces->push_back({mid[0], f[1], mid[1]});
    faces->push_back({mid[1], f[2], mid[2]});
    faces->push_back({mid[0], mid[1], mid[2]});
  } else if (num_split == 1) {
    const int k = mid[0] >= 0 ? 0 : mid[1] >= 0 ? 1 : 2;
    faces->push_back({f[k], mid[k], f[(k + 2) % 3]});
    faces->push_back({mid[k], f[(k + 1) % 3], f[(k + 2) % 3]});
  } else {
    const int k = mid[0] < 0 ? 0 : mid[1] < 0 ? 1 : 2;  // the edge left whole
    const int m1 = mid[(k + 1) % 3], m2 = mid[(k + 2) % 3];
    faces->push_back({f[k], f[(k + 1) % 3], m1});
    faces->push_back({f[k], m1, m2});
    faces->push_back({m1, f[(k + 2) % 3], m2});
  }
}

}  // namespace

double ProjectedEdgePixels(const std::vector<PinholeCamera>& cameras,
                           const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  double longest = 0;
  for (const PinholeCamera& camera : cameras) {
    const Eigen::Vector3d ca = camera.WorldToCamera(a), cb = camera.WorldToCamera(b);
    if (!(ca.z() > 0 && cb.z() > 0)) continue;
    const Eigen::Vector2d m = camera.CameraToPixel(0.5 * (ca + cb));
    if (!(m.x() >= 0 && m.y() >= 0 && m.x() < camera.width && m.y() < camera.height))
      continue;
    const double length = (camera.CameraToPixel(ca) - camera.CameraToPixel(cb)).norm();
    if (std::isfinite(length)) longest = std::max(longest, length);
  }
  return longest;
}

int SubdivideLongEdges(const std::vector<PinholeCamera>& cameras, double max_pixels,
                       TriangleMesh* mesh) {
  const int64_t num_faces = static_cast<int64_t>(mesh->faces.size());
  // Per face and edge: whether it is long (each edge is judged from both its faces
  // alike).
  std::vector<uint8_t> long_edge(3 * num_faces, 0);
  ParallelForRanges(0, num_faces, [&](int64_t begin, int64_t end, int) {
    for (int64_t i = begin; i < end; ++i) {
      const Eigen::Vector3i& f = mesh->faces[i];
      for (int k = 0; k < 3; ++k) {
        const int a = std::min(f[k], f[(k + 1) % 3]), b = std::max(f[k], f[(k + 1) % 3]);
        long_edge[3 * i + k] = ProjectedEdgePixels(cameras, mesh->vertices[a],
                                                   mesh->vertices[b]) > max_pixels;
      }
    }
  });
  std::unordered_map<uint64_t, int> midpoints;
  const bool has_colors = mesh->colors.size() == mesh->vertices.size();
  std::vector<Eigen::Vector3i> faces;
  faces.reserve(mesh->faces.size());
  for (int64_t i = 0; i < num_faces; ++i) {
    const Eigen::Vector3i f = mesh->faces[i];
    int mid[3] = {-1, -1, -1};
    for (int k = 0; k < 3; ++k) {
      if (!long_edge[3 * i + k]) continue;
      const int a = f[k], b = f[(k + 1) % 3];
      auto [it, inserted] =
          midpoints.emplace(EdgeKey(a, b), static_cast<int>(mesh->vertices.size()));
      if (inserted) {
        const Eigen::Vector3d m = 0.5 * (mesh->vertices[a] + mesh->vertices[b]);
        mesh->vertices.push_back(m);
        if (has_colors) {
          const Eigen::Vector3i c =
              (mesh->colors[a].cast<int>() + mesh->colors[b].cast<int>() +
               Eigen::Vector3i::Ones()) /
              2;
          mesh->colors.push_back(c.cast<uint8_t>());
        }
      }
      mid[k] = it->second;
    }
    SplitFace(f, mid, &faces);
  }
  if (midpoints.empty()) return 0;
  mesh->faces = std::move(faces);
  mesh->normals.clear();
  return static_cast<int>(midpoints.size());
}

}  // namespace fvs::mvs
