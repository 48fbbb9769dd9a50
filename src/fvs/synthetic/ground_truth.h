// The ground-truth sparse model of a synthetic scene in COLMAP's terms: one PINHOLE
// camera, the exact world-to-camera poses, and points3D sampled uniformly (by area) on
// the mesh with their exact projections as 2D observations in every view that sees them
// (inside the image, not occluded), so COLMAP's tools (model_analyzer, image_undistorter,
// stereo) accept it.
#pragma once

#include "colmap_ext/reconstruction.h"
#include "fvs/synthetic/synthetic_scene.h"

namespace fvs {

// Points seen by fewer than two views are dropped; at most
// scene.options.num_sparse_points are kept. Image ids are 1..n in view order, camera id
// 1, point ids 1..m. Deterministic.
colmap::Reconstruction SyntheticGroundTruthModel(const SyntheticScene& scene);

}  // namespace fvs
