// Mesh refinement by photo-consistency (issue 39 item 3): moves the proxy mesh's vertices
// along their normals to where the photos that see them agree, coarse to fine, with a
// smoothness term, bounded in time.
//
// The classical method (Vu, Labatut, Pons, Keriven 2012; OpenMVS's RefineMesh) descends
// the gradient of the similarity of image pairs reprojected through the mesh. This is a
// discrete variant of the same energy, written for a CPU and for meshes of a million
// vertices: per vertex and iteration, a search along the normal. At each offset t the
// vertex's tangent plane moved by t is the local surface; a patch of patch_size^2 points
// on it, spaced one pixel of the reference photo, is sampled in the reference (the photo
// that sees the vertex most frontally) and in up to num_sources other photos that see
// it; the score at t is the mean normalised cross-correlation (NCC) of the reference's
// samples with each other photo's, i.e. the similarity of the pairs reprojected through
// the moved surface. Photos see a vertex when it projects inside them, in front, not
// hidden by the mesh (their depth rendered from the current mesh) and at less than
// max_view_angle from its normal. The best offset (parabola through its neighbours) is
// the vertex's data term, weighted by its score, when the score reaches min_ncc and is
// a peak (min_peak above the worst offset); a patch without texture gives no data term.
// The data terms are then regularised (the smoothness term): Jacobi iterations of
//   x_v = (w_v d_v + smoothness * sum_u (n_u . n_v) x_u) / (w_v + smoothness * deg v)
// so a vertex with no data follows its neighbours and a lone outlier is pulled back; the
// result is clamped to the search range and applied, the normals and visibility are
// recomputed, and the next iteration searches again.
//
// Coarse to fine: num_levels levels of photo size (max_image_size halved per level
// coarser), num_iterations each; the search range is search_steps steps of half a pixel
// of the reference photo at that level, so the coarse levels move far and the fine ones
// precisely. max_seconds bounds the whole refinement: it stops after the iteration that
// crosses it (refined so far is kept, and the result says so).
//
// Detail: with max_edge_pixels > 0, each level first splits the edges longer than that in
// some photo at the level's size (mesh_subdivision.h), so the mesh can bend where the
// photos show more than its vertices do.
//
// Stable numbers: positions are double throughout; a vertex whose search or update is not
// finite is left where it is; without subdivision faces and their order are unchanged.
#pragma once

#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/util/image.h"

namespace fvs::mvs {

struct MeshRefinementOptions {
  // Off by default: on held-out views it did not pay (doc/real_scenes.md, session 24).
  bool enabled = false;
  int max_image_size = 800;    // photo size (longest side) of the finest level
  int num_levels = 3;          // coarse to fine, photo size halved per level
  int num_iterations = 2;      // per level
  int patch_size = 7;          // samples per side of the patch (odd)
  int search_steps = 4;        // offsets tried on each side of the vertex
  int num_sources = 4;         // photos compared with the reference per vertex
  double min_ncc = 0.3;        // mean NCC a data term must reach
  double min_peak = 0.05;      // by which it must beat the worst offset
  double max_view_angle = 75;  // degrees between a vertex's normal and a photo's ray
  double min_triangulation_angle = 2;  // degrees between reference and source rays
  double smoothness = 0.15;            // weight of each edge against a data weight (<= 1)
  int smoothing_iterations = 10;       // Jacobi iterations of the regularisation
  // Before each level, edges longer than this in some photo at that level are split
  // (mesh_subdivision.h), unless the mesh has max_vertices already; 0: no subdivision.
  double max_edge_pixels = 0;
  int max_vertices = 2000000;
  double max_seconds = 300;  // time bound of the whole refinement
  int num_threads = 0;       // <= 0: DefaultNumThreads()
  void Check() const;
  // Every field that changes the result, for prepare's fingerprint (not num_threads).
  std::string ToString() const;
};

struct MeshRefinementView {
  PinholeCamera camera;  // the mesh's frame
  Image photo;           // 1 or 3 channels in [0, 1], any size (resized here)
};

struct MeshRefinementResult {
  TriangleMesh mesh;  // moved (and added) vertices, their colours, faces; no normals
  int num_iterations_run = 0;
  size_t num_vertices_added = 0;  // by subdivision
  bool stopped_at_time_bound = false;
  // Mean NCC at the surface itself (no search) over the vertices with texture that two
  // photos see, at the finest level: of the input mesh and of the refined one.
  double ncc_before = 0;
  double ncc_after = 0;
  double first_data_share = 0;  // share of vertices with a data term, first iteration
  double last_data_share = 0;
  double median_move_pixels = 0;  // |displacement| of moved vertices, finest-level pixels
  double seconds = 0;
  std::string Summary() const;  // one line for the log
};

// Refines `mesh` against `views` (at least two; else the mesh is returned unchanged).
// Throws fvs::Error when the options are invalid.
MeshRefinementResult RefineMesh(const std::vector<MeshRefinementView>& views,
                                const TriangleMesh& mesh,
                                const MeshRefinementOptions& options);

}  // namespace fvs::mvs
