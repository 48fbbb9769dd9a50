// Rendering the synthetic scene exactly: one ray per pixel centre (COLMAP convention,
// pixel (x, y) centred at (x + 0.5, y + 0.5)) for depth and normals, s x s stratified
// rays per pixel for colour. Lambert shading of the procedural albedo under two fixed
// directional lights plus ambient (view-independent, as multi-view stereo and SfM
// assume), then gamma 1/2.2. Rows are rendered in parallel; a pixel depends only on its
// own rays, so the thread count never changes the result.
#pragma once

#include <Eigen/Core>

#include "fvs/geometry/camera.h"
#include "fvs/synthetic/synthetic_scene.h"
#include "fvs/util/image.h"

namespace fvs {

// Any output may be null. color: 3 channels in [0, 1] (sRGB). depth: 1 channel,
// camera-frame z of the pixel-centre ray's hit (0 where it hits nothing). normals: 3
// channels, unit camera-frame normals of the hit face turned towards the camera (0 where
// nothing is hit). supersampling <= 0 takes scene.options.supersampling. The camera may
// be any pinhole camera (any size and pose), not only one of scene.cameras.
void RenderSyntheticView(const SyntheticScene& scene, const PinholeCamera& camera,
                         Image* color, Image* depth, Image* normals,
                         int supersampling = 0, int num_threads = 0);

// Linear-RGB radiance of the surface point `point` on face `face` seen along
// `view_direction` (from the camera towards the point): albedo times shading, not clamped
// to 1.
Eigen::Vector3d ShadeSyntheticSurface(const SyntheticScene& scene, int face,
                                      const Eigen::Vector3d& point,
                                      const Eigen::Vector3d& view_direction);

// Linear value in [0, 1] -> sRGB-like value (gamma 1/2.2), clamped.
double SyntheticGamma(double linear);

}  // namespace fvs
