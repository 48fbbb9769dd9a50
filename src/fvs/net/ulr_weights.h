// Unstructured Lumigraph Rendering weights (Buehler et al., SIGGRAPH 2001): the blend the
// classical `ulr` method renders with, and the prior that fvs_fast's per-source
// confidences start from (ModelConfig::ulr_prior), so that the untrained network renders
// exactly what `ulr` renders and training can only add to it. No torch: the renderer,
// the trainer and the tests share this code.
//   penalty_i = angle_i + resolution_weight * resolution_i
//   angle_i: angle at the surface point between the rays to the target and to source i
//   resolution_i: max(0, footprint_i / footprint_target - 1), footprint = distance /
//   focal k-nearest: only the k best penalties take part; threshold = the (k+1)-th
//   penalty (or twice the worst when fewer candidates), w_i = (1 - p_i / threshold) /
//   p_i, normalised.
// The 1 / p_i factor (as in later ULR implementations) makes a target that coincides with
// a source reproduce that source exactly.
//
// Pixels without a surface (seen at infinity, geometry/warp.h) have no point to measure
// the angle at: at infinity every source's ray is parallel to the target's and all angles
// are 0. They are weighed at the point D_far along their ray instead
// (UlrPointAtInfinity), D_far = kUlrFarFactor (10) times the distance from the target
// centre to the farthest of its sources' centres (1 when they all coincide with it).
// There the angle is about the source centre's distance from the target ray over D_far
// (at most 0.1 rad), so the sources nearest to the line of sight weigh most, as ULR does
// for a distant surface, and the weights depend on the sources' layout only, not on the
// scene's scale.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fvs {

struct UlrOptions {
  double resolution_weight = 0.2;  // weight of the resolution penalty vs the angle (rad)
  int num_blend = 4;               // k-nearest: best sources blended per pixel
  // Throws fvs::Error("ULR options", ...): resolution_weight finite and >= 0, num_blend
  // >= 1.
  void Check() const;
};

// log() of weights below this is clamped to it: finite, and e^-9.2 of the weight.
constexpr double kUlrWeightFloor = 1e-4;

// Normalised weights of n candidates from their penalties (>= 0). Only the `k` smallest
// take part. Always finite, sum 1 when n > 0.
void UlrWeights(const double* penalties, int n, int k, double* weights);

// The ULR penalty of one source at a point, all in one frame.
double UlrPenalty(const Eigen::Vector3d& point, const Eigen::Vector3d& target_center,
                  double target_focal, const Eigen::Vector3d& source_center,
                  double source_focal, double resolution_weight);

// The sources of one target view: their centres in the target's camera frame (the
// target centre is the origin) and focal lengths (sqrt(fx fy), pixels).
struct UlrSources {
  double target_focal = 1;
  std::vector<Eigen::Vector3d> centers;
  std::vector<double> focals;
  int size() const { return static_cast<int>(centers.size()); }
};

// D_far above, as a multiple of the farthest source centre's distance.
constexpr double kUlrFarFactor = 10.0;

// D_far of these sources (> 0 and finite).
double UlrFarDistance(const UlrSources& sources);

// The point a pixel without a surface is weighed at: D_far along its ray direction
// (target camera frame, any length > 0).
Eigen::Vector3d UlrPointAtInfinity(const Eigen::Vector3d& ray, double far_distance);

// Weights of every source at one surface point (target camera frame): 0 where
// sees[s] is false, the others sum to 1. Returns how many sources see the point (0: all
// weights 0).
int UlrPointWeights(const Eigen::Vector3d& point, const UlrSources& sources,
                    const bool* sees, const UlrOptions& settings, double* weights);

// log(max(weight, kUlrWeightFloor)) of every source at every pixel: points are
// num_pixels x 3 doubles (target camera frame, row-major), sees and log_weights are
// sources.size() x num_pixels (source-major; sees > 0.5 = the source sees the pixel).
// A pixel no source sees gets the floor everywhere.
void UlrLogWeights(const double* points, int64_t num_pixels, const UlrSources& sources,
                   const float* sees, const UlrOptions& settings, float* log_weights,
                   int num_threads = 0);

}  // namespace fvs
