#include "fvs/synthetic/bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "fvs/util/error.h"

namespace fvs::synthetic {
namespace {

constexpr int kLeafSize = 4;
constexpr int kNumBins = 16;

double HalfArea(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d d = (hi - lo).cwiseMax(0.0);
  return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
}

}  // namespace

MeshBvh::MeshBvh(const TriangleMesh& mesh) {
  const int n = static_cast<int>(mesh.faces.size());
  triangles_.resize(n);
  std::vector<Eigen::Vector3d> centroids(n), lo(n), hi(n);
  for (int f = 0; f < n; ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    for (int k = 0; k < 3; ++k) {
      if (face[k] < 0 || face[k] >= static_cast<int>(mesh.vertices.size())) {
        throw Error("MeshBvh",
                    "face " + std::to_string(f) + " has a vertex index out of range");
      }
    }
    const Eigen::Vector3d& a = mesh.vertices[face[0]];
    const Eigen::Vector3d& b = mesh.vertices[face[1]];
    const Eigen::Vector3d& c = mesh.vertices[face[2]];
    Triangle& t = triangles_[f];
    t.v0 = a;
    t.e1 = b - a;
    t.e2 = c - a;
    const Eigen::Vector3d cross = t.e1.cross(t.e2);
    const double norm = cross.norm();
    t.normal = norm > 0 ? Eigen::Vector3d(cross / norm) : Eigen::Vector3d(0, 0, 1);
    lo[f] = a.cwiseMin(b).cwiseMin(c);
    hi[f] = a.cwiseMax(b).cwiseMax(c);
    centroids[f] = (a + b + c) / 3.0;
  }
  order_.resize(n);
  for (int f = 0; f < n; ++f) order_[f] = f;
  nodes_.reserve(2 * n / kLeafSize + 2);
  if (n > 0) Build(0, n, &centroids, &lo, &hi);
}

int MeshBvh::Build(int begin, int end, std::vector<Eigen::Vector3d>* centroids,
                   std::vector<Eigen::Vector3d>* lo, std::vector<Eigen::Vector3d>* hi) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d box_lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d box_hi = -box_lo;
  Eigen::Vector3d c_lo = box_lo, c_hi = box_hi;
  for (int i = begin; i < end; ++i) {
    const int f = order_[i];
    box_lo = box_lo.cwiseMin((*lo)[f]);
    box_hi = box_hi.cwiseMax((*hi)[f]);
    c_lo = c_lo.cwiseMin((*centroids)[f]);
    c_hi = c_hi.cwiseMax((*centroids)[f]);
  }
  nodes_[index].lo = box_lo;
  nodes_[index].hi = box_hi;
  const int count = end - begin;
  int axis = 0;
  (c_hi - c_lo).maxCoeff(&axis);
  const double extent = c_hi[axis] - c_lo[axis];
  if (count <= kLeafSize || !(extent > 0)) {
    nodes_[index].first = begin;
    nodes_[index].count = count;
    return index;
  }

  // Binned SAH along the widest centroid axis.
  struct Bin {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::max());
    int count = 0;
  };
  std::array<Bin, kNumBins> bins;
  auto bin_of = [&](int f) {
    const int b =
        static_cast<int>(kNumBins * ((*centroids)[f][axis] - c_lo[axis]) / extent);
    return std::clamp(b, 0, kNumBins - 1);
  };
  for (int i = begin; i < end; ++i) {
    const int f = order_[i];
    Bin& bin = bins[bin_of(f)];
    bin.lo = bin.lo.cwiseMin((*lo)[f]);
    bin.hi = bin.hi.cwiseMax((*hi)[f]);
    ++bin.count;
  }
  std::array<double, kNumBins> right_cost{};
  {
    Bin acc;
    for (int b = kNumBins - 1; b > 0; --b) {
      acc.lo = acc.lo.cwiseMin(bins[b].lo);
      acc.hi = acc.hi.cwiseMax(bins[b].hi);
      acc.count += bins[b].count;
      right_cost[b] = acc.count ? HalfArea(acc.lo, acc.hi) * acc.count : 0.0;
    }
  }
  double best_cost = std::numeric_limits<double>::max();
  int best_split = -1;
  {
    Bin acc;
    for (int b = 0; b < kNumBins - 1; ++b) {
      acc.lo = acc.lo.cwiseMin(bins[b].lo);
      acc.hi = acc.hi.cwiseMax(bins[b].hi);
      acc.count += bins[b].count;
      if (acc.count == 0 || acc.count == count) continue;
      const double cost = HalfArea(acc.lo, acc.hi) * acc.count + right_cost[b + 1];
      if (cost < best_cost) {
        best_cost = cost;
        best_split = b;
      }
    }
  }
  int middle;
  if (best_split < 0) {
    middle = begin + count / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + middle,
                     order_.begin() + end, [&](int a, int b) {
                       const double ca = (*centroids)[a][axis],
                                    cb = (*centroids)[b][axis];
                       return ca < cb || (ca == cb && a < b);
                     });
  } else {
    middle = static_cast<int>(
        std::stable_partition(order_.begin() + begin, order_.begin() + end,
                              [&](int f) { return bin_of(f) <= best_split; }) -
        order_.begin());
  }
  Build(begin, middle, centroids, lo, hi);
  const int right = Build(middle, end, centroids, lo, hi);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

bool MeshBvh::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                        double t_min, double t_max, RayHit* hit) const {
  if (nodes_.empty()) return false;
  const Eigen::Vector3d inv(1.0 / direction.x(), 1.0 / direction.y(),
                            1.0 / direction.z());
  // Slab test; infinities from zero direction components behave as intended, but 0 * inf
  // gives NaN for a ray starting exactly on a slab plane, so NaN compares are made to
  // fail towards "hit" (conservative).
  auto box_entry = [&](const Node& node, double t_far) {
    double t0 = t_min, t1 = t_far;
    for (int a = 0; a < 3; ++a) {
      double ta = (node.lo[a] - origin[a]) * inv[a];
      double tb = (node.hi[a] - origin[a]) * inv[a];
      if (ta > tb) std::swap(ta, tb);
      if (ta > t0) t0 = ta;
      if (tb < t1) t1 = tb;
    }
    return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
  };

  bool found = false;
  double best = t_max;
  int stack[256];
  int top = 0;
  if (box_entry(nodes_[0], best) == std::numeric_limits<double>::infinity()) return false;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.count > 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int f = order_[i];
        const Triangle& tri = triangles_[f];
        const Eigen::Vector3d p = direction.cross(tri.e2);
        const double det = tri.e1.dot(p);
        if (det == 0.0) continue;
        const double inv_det = 1.0 / det;
        const Eigen::Vector3d s = origin - tri.v0;
        const double u = s.dot(p) * inv_det;
        // A tiny tolerance so that rays through shared edges never slip between
        // triangles.
        constexpr double kEdgeTolerance = 1e-12;
        if (u < -kEdgeTolerance || u > 1 + kEdgeTolerance) continue;
        const Eigen::Vector3d q = s.cross(tri.e1);
        const double v = direction.dot(q) * inv_det;
        if (v < -kEdgeTolerance || u + v > 1 + kEdgeTolerance) continue;
        const double t = tri.e2.dot(q) * inv_det;
        if (t > t_min && t < best) {
          best = t;
          found = true;
          hit->t = t;
          hit->face = f;
          hit->u = u;
          hit->v = v;
        }
      }
      continue;
    }
    const int left = static_cast<int>(&node - nodes_.data()) + 1;
    const int right = node.first;
    const double tl = box_entry(nodes_[left], best);
    const double tr = box_entry(nodes_[right], best);
    // Push the farther child first so the nearer one is visited first.
    if (tl <= tr) {
      if (tr != std::numeric_limits<double>::infinity() && top < 256)
        stack[top++] = right;
      if (tl != std::numeric_limits<double>::infinity() && top < 256) stack[top++] = left;
    } else {
      if (tl != std::numeric_limits<double>::infinity() && top < 256) stack[top++] = left;
      if (tr != std::numeric_limits<double>::infinity() && top < 256)
        stack[top++] = right;
    }
  }
  return found;
}

}  // namespace fvs::synthetic
