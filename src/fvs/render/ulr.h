// Unstructured Lumigraph Rendering (Buehler et al., SIGGRAPH 2001) as a classical
// baseline without a network: the K selected sources' colours, warped with the same
// target depth and masks as the network sees, blended per pixel with ULR weights:
//   penalty_i = angle_i + resolution_weight * resolution_i
//   angle_i: angle at the surface point between the rays to the target and to source i
//   resolution_i: max(0, footprint_i / footprint_target - 1), footprint = distance /
//   focal k-nearest: only the k best penalties take part; threshold = the (k+1)-th
//   penalty (or twice the worst when fewer candidates), w_i = (1 - p_i / threshold) /
//   p_i, normalised.
// The 1 / p_i factor (as in later ULR implementations) makes a target that coincides with
// a source reproduce that source exactly. Pixels no source sees stay black (coverage 0).
#pragma once

#include <memory>

#include "fvs/render/method.h"

namespace fvs {

// Normalised weights of n candidates from their penalties (>= 0). Only the `k` smallest
// take part. Always finite, sum 1 when n > 0.
void UlrWeights(const double* penalties, int n, int k, double* weights);

// The ULR penalty of one source at a point, all in one frame.
double UlrPenalty(const Eigen::Vector3d& point, const Eigen::Vector3d& target_center,
                  double target_focal, const Eigen::Vector3d& source_center,
                  double source_focal, double resolution_weight);

std::unique_ptr<Method> CreateUlrMethod(const RenderOptions& options);
// The best-ranked source alone, reprojected (black where it does not see the pixel).
std::unique_ptr<Method> CreateNearestMethod(const RenderOptions& options);

}  // namespace fvs
