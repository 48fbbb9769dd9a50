// RayCastDepth: the reference the rasteriser is checked against. One ray per pixel
// centre, intersected (Moller-Trumbore, double) with the faces in the camera frame
// through a bounding-volume hierarchy (median splits), so a 1 M-face mesh takes seconds,
// not hours. Deliberately shares no code with the rasteriser.
#include <algorithm>
#include <cmath>
#include <limits>

#include "fvs/geometry/rasterizer.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {
namespace {

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi =
      Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  void Extend(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void Extend(const Box& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
};

struct Node {
  Box box;
  int first = 0, count = 0;  // leaf: faces order[first, first + count)
  int left = -1, right = -1;
};

class Bvh {
 public:
  Bvh(const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3i>& faces)
      : v_(v), faces_(faces) {
    for (int i = 0; i < static_cast<int>(faces.size()); ++i) {
      const Eigen::Vector3i& f = faces[i];
      if (v[f[0]].allFinite() && v[f[1]].allFinite() && v[f[2]].allFinite()) {
        order_.push_back(i);
      }
    }
    centroids_.resize(faces.size());
    for (int i : order_) {
      const Eigen::Vector3i& f = faces[i];
      centroids_[i] = (v[f[0]] + v[f[1]] + v[f[2]]) / 3.0;
    }
    nodes_.reserve(2 * order_.size() / 4 + 2);
    if (!order_.empty()) Build(0, static_cast<int>(order_.size()));
  }

  // Nearest hit with t > 0 along origin + t * dir (origin at the camera centre).
  double Cast(const Eigen::Vector3d& dir) const {
    double best = std::numeric_limits<double>::infinity();
    if (nodes_.empty()) return best;
    const Eigen::Vector3d inv = dir.cwiseInverse();
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!HitsBox(node.box, inv, best)) continue;
      if (node.left < 0) {
        for (int k = node.first; k < node.first + node.count; ++k) {
          Intersect(order_[k], dir, &best);
        }
        continue;
      }
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
    return best;
  }

 private:
  int Build(int begin, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    Box box, centroid_box;
    for (int k = begin; k < end; ++k) {
      const Eigen::Vector3i& f = faces_[order_[k]];
      for (int j = 0; j < 3; ++j) box.Extend(v_[f[j]]);
      centroid_box.Extend(centroids_[order_[k]]);
    }
    nodes_[index].box = box;
    if (end - begin <= 4) {
      nodes_[index].first = begin;
      nodes_[index].count = end - begin;
      return index;
    }
    int axis;
    (centroid_box.hi - centroid_box.lo).maxCoeff(&axis);
    const int mid = (begin + end) / 2;
    std::nth_element(
        order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
        [&](int a, int b) { return centroids_[a][axis] < centroids_[b][axis]; });
    const int left = Build(begin, mid);
    const int right = Build(mid, end);
    nodes_[index].left = left;
    nodes_[index].right = right;
    return index;
  }

  static bool HitsBox(const Box& box, const Eigen::Vector3d& inv, double t_max) {
    double t0 = 0, t1 = t_max;
    for (int a = 0; a < 3; ++a) {
      double ta = box.lo[a] * inv[a], tb = box.hi[a] * inv[a];
      if (std::isnan(ta) || std::isnan(tb)) {  // 0 * inf: ray parallel, inside the slab
        if (box.lo[a] > 0 || box.hi[a] < 0) return false;
        continue;
      }
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }

  void Intersect(int face, const Eigen::Vector3d& dir, double* best) const {
    const Eigen::Vector3i& f = faces_[face];
    const Eigen::Vector3d& v0 = v_[f[0]];
    const Eigen::Vector3d e1 = v_[f[1]] - v0, e2 = v_[f[2]] - v0;
    const Eigen::Vector3d p = dir.cross(e2);
    const double det = e1.dot(p);
    if (det == 0 || !std::isfinite(det)) return;
    const Eigen::Vector3d s = -v0;
    const double b1 = s.dot(p) / det;
    if (b1 < 0 || b1 > 1) return;
    const Eigen::Vector3d q = s.cross(e1);
    const double b2 = dir.dot(q) / det;
    if (b2 < 0 || b1 + b2 > 1) return;
    const double t = e2.dot(q) / det;
    if (t > 0 && t < *best) *best = t;
  }

  const std::vector<Eigen::Vector3d>& v_;
  const std::vector<Eigen::Vector3i>& faces_;
  std::vector<int> order_;
  std::vector<Eigen::Vector3d> centroids_;
  std::vector<Node> nodes_;
};

}  // namespace

Image RayCastDepth(const TriangleMesh& mesh, const PinholeCamera& camera, int y0,
                   int y1) {
  if (!camera.IsValid()) throw Error("RayCastDepth", "invalid camera");
  if (y1 < 0 || y1 > camera.height) y1 = camera.height;
  y0 = std::clamp(y0, 0, y1);
  const int64_t n = static_cast<int64_t>(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    if (f.minCoeff() < 0 || f.maxCoeff() >= n) {
      throw Error("RayCastDepth", "face refers to a vertex index out of range");
    }
  }
  std::vector<Eigen::Vector3d> v(mesh.vertices.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = camera.WorldToCamera(mesh.vertices[i]);
  const Bvh bvh(v, mesh.faces);
  Image depth(camera.width, camera.height, 1);
  ParallelFor(y0, y1, [&](int64_t y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d dir((x + 0.5 - camera.cx) / camera.fx,
                                (y + 0.5 - camera.cy) / camera.fy, 1.0);
      const double t = bvh.Cast(dir);
      const bool hit = t <= std::numeric_limits<float>::max();  // false for +inf too
      depth.at(x, static_cast<int>(y)) = hit ? static_cast<float>(t) : 0.0f;
    }
  });
  return depth;
}

}  // namespace fvs
