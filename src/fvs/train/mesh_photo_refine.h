// Per-scene refinement of the proxy mesh by the photo-consistency of its own renders
// (`colmap view_synthesis_refine`, train/scene_refine.h). Every photo in the geometry is
// rendered leave-one-out from its nearest other photos through the mesh, as `ulr`
// renders a novel view, and the vertices move to lower the colour error of those renders
// against the photos: the variational refinement of Vu et al. (2012), with the renderer's
// own blend as the score instead of pairwise similarity. The gradient reaches a vertex
// through the ray-plane intersection of each pixel's face (the pixel's surface point)
// and the bilinear sampling of the sources there; a Laplacian term on the displacements
// keeps the mesh smooth where the photos say nothing (textureless parts). Which face a
// pixel sees, which sources see its point (the occlusion test) and the blend weights
// (ULR) are frozen between re-rasterisations of the moved mesh. Geometry in double
// precision.
#pragma once

#include <functional>
#include <vector>

#include "fvs/geometry/mesh.h"

namespace fvs {

struct PackedScene;

struct MeshPhotoRefineOptions {
  double seconds = 600;         // wall-time budget of the optimisation (> 0)
  int num_sources = 4;          // sources per leave-one-out target
  int pixels_per_step = 65536;  // sampled over all targets' surface pixels
  double step = 0.01;           // Adam step size, in median edge lengths
  double smoothness = 0.05;     // weight of the Laplacian term (see the .cc)
  double max_move = 2.0;        // displacement bound, in median edge lengths
  int steps_per_raster = 40;    // re-rasterise (faces, visibility, weights) this often
  // Coarse to fine: the budget in equal shares at photos box-blurred with radius 2^L,
  // ..., 2 pixels, then sharp (0: sharp only).
  int coarse_levels = 0;
  double charbonnier_eps = 0.01;  // of the colour error, in [0,1] units
  double occlusion_tolerance = 0.01;
  int seed = 0;
  int num_threads = 0;  // <= 0: default
  bool quiet = false;   // no progress lines
  // Optional: called between steps; true stops the optimisation (the result so far is
  // returned).
  std::function<bool()> stop;
  // Optional: called every checkpoint_seconds with the mesh so far and the steps done
  // (a killed run resumes from what it saved).
  std::function<void(const TriangleMesh&, int)> checkpoint;
  double checkpoint_seconds = 60;
  void Check() const;  // throws fvs::Error("view_synthesis_refine", ...)
};

struct MeshPhotoRefineResult {
  TriangleMesh mesh;  // the moved vertices; faces, normals dropped, colours kept
  int steps = 0;
  double seconds = 0;
  // Mean Charbonnier error over every target's surface pixels (all of them, not a
  // sample), before and after, each on its own rasterisation.
  double initial_error = 0, final_error = 0;
  int num_targets = 0;
  double median_edge = 0;                // of the input mesh, in scene units
  double median_move = 0, max_move = 0;  // vertex displacements, in median edges
};

// `mesh` is in the packed scene's frame (world minus the pack's origin).
// `initial_offsets` (one per vertex, or empty) resumes an earlier run; the result's
// vertices are the mesh's plus the offsets found. A vertex that is not finite stays as it
// is (the rasteriser skips its faces); no other becomes non-finite. Throws fvs::Error
// when no view has a source.
MeshPhotoRefineResult RefineMeshByPhotoConsistency(
    const PackedScene& scene, const TriangleMesh& mesh,
    const MeshPhotoRefineOptions& options,
    const std::vector<Eigen::Vector3d>& initial_offsets = {});

}  // namespace fvs
