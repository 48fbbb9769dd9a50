// Unstructured Lumigraph Rendering (Buehler et al., SIGGRAPH 2001) as a classical
// baseline without a network: the K selected sources' colours, warped with the same
// target depth and masks as the network sees and sampled bicubically (or bilinearly, as
// the network samples: RenderOptions::interpolation), blended per pixel with ULR weights
// (net/ulr_weights.h, shared with the network's prior). Pixels without a surface are
// blended from the sources that see them at infinity (geometry/warp.h); pixels no source
// sees stay black (coverage 0).
#pragma once

#include <memory>

#include "fvs/net/ulr_weights.h"
#include "fvs/render/method.h"

namespace fvs {

struct PreparedTarget;
class Scene;
struct TargetView;

// The surface point of target pixel (x, y) that ULR weighs the sources at, in the
// target's camera frame: along the pixel centre's ray at the target depth, or, where the
// pixel has no surface, UlrPointAtInfinity at far_distance (UlrFarDistance of the
// target's sources; net/ulr_weights.h).
Eigen::Vector3d UlrSurfacePoint(const PinholeCamera& target, const Image& depth, int x,
                                int y, double far_distance);

// The selected sources of a prepared target as UlrSources (centres in the target frame).
UlrSources MakeUlrSources(const Scene& scene, const TargetView& target,
                          const PreparedTarget& prepared);

std::unique_ptr<Method> CreateUlrMethod(const RenderOptions& options);
// The best-ranked source alone, reprojected (black where it does not see the pixel).
std::unique_ptr<Method> CreateNearestMethod(const RenderOptions& options);

}  // namespace fvs
