#include "fvs/mvs/isolated_points.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>

#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs::mvs {
namespace {

// A static kd-tree over point indices (median splits, leaves of up to 8 points) for
// k-nearest-neighbour queries; no CGAL, so it builds everywhere.
class KdTree {
 public:
  explicit KdTree(const std::vector<Eigen::Vector3d>& points) : points_(points) {
    order_.resize(points.size());
    std::iota(order_.begin(), order_.end(), 0u);
    if (!points.empty()) Build(0, static_cast<uint32_t>(points.size()));
  }

  // Mean distance from point `self` to its k nearest other points.
  double MeanNeighborDistance(uint32_t self, int k) const {
    std::priority_queue<double> best;  // squared distances, largest on top
    Search(0, points_[self], self, k, &best);
    double sum = 0;
    const size_t n = best.size();
    while (!best.empty()) {
      sum += std::sqrt(best.top());
      best.pop();
    }
    return n ? sum / static_cast<double>(n) : 0.0;
  }

 private:
  struct Node {
    uint32_t begin, end;  // range of order_
    int axis = -1;        // -1: leaf
    double split = 0;
    uint32_t left = 0, right = 0;
  };

  uint32_t Build(uint32_t begin, uint32_t end) {
    const uint32_t id = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back({begin, end});
    if (end - begin <= kLeafSize) return id;
    Eigen::Vector3d lo = points_[order_[begin]], hi = lo;
    for (uint32_t i = begin; i < end; ++i) {
      lo = lo.cwiseMin(points_[order_[i]]);
      hi = hi.cwiseMax(points_[order_[i]]);
    }
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(
        order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
        [&](uint32_t a, uint32_t b) { return points_[a][axis] < points_[b][axis]; });
    const double split = points_[order_[mid]][axis];
    const uint32_t left = Build(begin, mid);
    const uint32_t right = Build(mid, end);
    nodes_[id].axis = axis;
    nodes_[id].split = split;
    nodes_[id].left = left;
    nodes_[id].right = right;
    return id;
  }

  void Search(uint32_t id, const Eigen::Vector3d& q, uint32_t self, int k,
              std::priority_queue<double>* best) const {
    const Node& node = nodes_[id];
    if (node.axis < 0) {
      for (uint32_t i = node.begin; i < node.end; ++i) {
        if (order_[i] == self) continue;
        const double d2 = (points_[order_[i]] - q).squaredNorm();
        if (static_cast<int>(best->size()) < k) {
          best->push(d2);
        } else if (d2 < best->top()) {
          best->pop();
          best->push(d2);
        }
      }
      return;
    }
    const double diff = q[node.axis] - node.split;
    const uint32_t near = diff < 0 ? node.left : node.right;
    const uint32_t far = diff < 0 ? node.right : node.left;
    Search(near, q, self, k, best);
    if (static_cast<int>(best->size()) < k || diff * diff < best->top()) {
      Search(far, q, self, k, best);
    }
  }

  static constexpr uint32_t kLeafSize = 8;
  const std::vector<Eigen::Vector3d>& points_;
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace

void IsolatedPointOptions::Check() const {
  Require(num_neighbors >= 0 && num_neighbors <= 256, "delaunay mesher",
          "isolated_point_neighbors must be in [0, 256], not " +
              std::to_string(num_neighbors));
  Require(std::isfinite(factor) && factor >= 1, "delaunay mesher",
          "isolated_point_factor must be >= 1, not " + std::to_string(factor));
}

std::vector<double> MeanNeighborDistances(const std::vector<Eigen::Vector3d>& points,
                                          int k, int num_threads) {
  std::vector<double> spacing(points.size(), 0.0);
  if (points.size() < 2 || k <= 0) return spacing;
  // Centred, so that far-away scenes keep their precision in the squared distances.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  std::vector<Eigen::Vector3d> centred(points.size());
  for (size_t i = 0; i < points.size(); ++i) centred[i] = points[i] - centre;
  const KdTree tree(centred);
  ParallelFor(
      0, static_cast<int64_t>(points.size()),
      [&](int64_t i) {
        spacing[i] = tree.MeanNeighborDistance(static_cast<uint32_t>(i), k);
      },
      num_threads > 0 ? num_threads : DefaultNumThreads());
  return spacing;
}

std::vector<bool> FindIsolatedPoints(const std::vector<Eigen::Vector3d>& points,
                                     const IsolatedPointOptions& options) {
  options.Check();
  std::vector<bool> isolated(points.size(), false);
  const int k = options.num_neighbors;
  if (k == 0 || points.size() < static_cast<size_t>(k) + 1) return isolated;
  const std::vector<double> spacing =
      MeanNeighborDistances(points, k, options.num_threads);
  std::vector<double> sorted = spacing;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double threshold = options.factor * sorted[sorted.size() / 2];
  for (size_t i = 0; i < points.size(); ++i) isolated[i] = spacing[i] > threshold;
  return isolated;
}

}  // namespace fvs::mvs
