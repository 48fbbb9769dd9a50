// Isolated fused points: stereo on textureless or dark background (Middlebury's black
// cloth, sky) leaves a few points far from everything else, and the graph cut then spans
// huge triangles from the object to them that no long-edge percentile removes. A point is
// isolated when the mean distance to its k nearest neighbours exceeds `factor` times the
// median of that mean over all points (the statistical outlier removal of PCL / OpenMVS,
// with a median so that the outliers do not set their own threshold).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fvs::mvs {

struct IsolatedPointOptions {
  int num_neighbors = 8;  // k; 0 = keep every point
  double factor = 6.0;
  int num_threads = -1;  // <= 0: DefaultNumThreads()
  void Check() const;    // throws fvs::Error
};

// Per point, the mean distance to its k nearest other points (all of them when there are
// fewer); 0 for a lone point.
std::vector<double> MeanNeighborDistances(const std::vector<Eigen::Vector3d>& points,
                                          int k, int num_threads = -1);

// Per point, true when it is isolated. Fewer than k + 1 points: none is.
std::vector<bool> FindIsolatedPoints(const std::vector<Eigen::Vector3d>& points,
                                     const IsolatedPointOptions& options);

}  // namespace fvs::mvs
