// Delaunay graph-cut surface reconstruction of a fused MVS point cloud: the method of
// Labatut, Pons and Keriven 2009 ("Robust and efficient surface reconstruction from range
// data") with the visibility weighting of Jancosek and Pajdla 2011, following
// COLMAP 3.8's delaunay_mesher (same options, same defaults, same weights):
//   1. 3D Delaunay triangulation (CGAL, EPICK) of the points; with max_proj_dist > 0 a
//   point
//      is merged into the cell it falls in when all four cell vertices project within
//      max_proj_dist pixels and max_depth_dist relative depth of it in every image that
//      sees it (COLMAP's sub-sampled triangulation).
//   2. For every point and every image that sees it, the segment point -> camera centre
//   is
//      walked through the triangulation: each crossed facet gets a visibility weight
//      (free space, falling off near the point with the distance sigma), the cell holding
//      the camera (or the hull cell the segment leaves through) gets a source (outside)
//      weight, the cell just behind the point gets a sink (inside) weight.
//   3. s-t graph: cells are nodes, facets are edges (visibility weight + surface-quality
//   term
//      1 - min(cos) of the facet/circumsphere angles of Labatut et al., Fig. 9); min cut
//      by Boost.Graph's Boykov-Kolmogorov max-flow.
//   4. Surface = facets between inside and outside cells, oriented outward
//   (counter-clockwise
//      seen from outside); triangles whose longest side exceeds max_side_length_factor x
//      the max_side_length_percentile of longest sides are dropped; unreferenced vertices
//      go.
// Everything runs in scene-centred double coordinates (the point mean is subtracted and
// added back on output), so a scene far from the origin meshes as one at the origin.
//
// Differences from COLMAP, on purpose: rays are cast once per (triangulation vertex,
// image) pair with the summed weight of the input points merged into that vertex (OpenMVS
// does the same; COLMAP casts one ray per input point, which costs the same result many
// times over), and the walk starts at the point and goes towards the camera from the cell
// incident to the vertex (no point location per ray). Unused vertices are removed (COLMAP
// keeps them).
//
// This header compiles without CGAL. When the library was built without CGAL or
// Boost.Graph (FVS_HAVE_CGAL undefined) the functions below are not linked: callers test
// DelaunayMesherAvailable() (or FVS_HAVE_CGAL) first.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"

namespace fvs::mvs {

constexpr bool DelaunayMesherAvailable() {
#ifdef FVS_HAVE_CGAL
  return true;
#else
  return false;
#endif
}

struct DelaunayMeshingOptions {
  // Merge input points into one triangulation vertex when they reproject within this many
  // pixels of all vertices of the cell they fall in (0 = keep every point). COLMAP: 20.
  // 40 was best of 5, 20, 30, 40, 60 on the held-out views of five tuning scenes (with
  // max_side_spacing_factor 0: doc/real_scenes.md, session 29); 5 was worst: more
  // vertices carry more of the fused points' noise into the surface.
  double max_proj_dist = 40.0;
  // ... and their depths differ by less than this fraction.
  double max_depth_dist = 0.05;
  // Weight of a point's rays: 1 - exp(-n^2 / (2 sigma^2)) for a point seen in n images,
  // so points seen by few images (likely outliers) count little.
  double visibility_sigma = 3.0;
  // The distance sigma (falloff of the free-space weight near the point) is this factor
  // times the 25th percentile of the triangulation's edge lengths.
  double distance_sigma_factor = 1.0;
  // Weight of the surface-quality (smoothness) term.
  double quality_regularization = 1.0;
  // Long-edge filter: drop faces whose longest side exceeds factor x percentile.
  double max_side_length_factor = 25.0;
  double max_side_length_percentile = 95.0;
  // Not in COLMAP: before triangulation, drop points whose mean distance to their
  // isolated_point_neighbors nearest points exceeds isolated_point_factor x the median of
  // that distance (isolated_points.h): stray background points otherwise anchor huge
  // triangles. 0 neighbours = keep every point, as COLMAP.
  int isolated_point_neighbors = 8;
  double isolated_point_factor = 6.0;
  // Not in COLMAP: also drop faces whose longest side exceeds this factor x the largest
  // local point spacing (mean distance to the 8 nearest points) at its vertices. Faces
  // that bridge empty space between parts of the cloud fail it; faces in sparse regions,
  // or joining a sparse region to a dense one, do not. 0 = off, as COLMAP, the default
  // since the backdrop (scene/backdrop.h) fills what lies beyond the mesh: the faces it
  // dropped were mostly the true surface across textureless parts (a white table top,
  // a black dinosaur's flanks), and held-out views of the tuning scenes lost 0.2-2 dB
  // by it (doc/real_scenes.md, session 29).
  double max_side_spacing_factor = 0.0;
  // Not in COLMAP: the SfM points of W/sparse join the fused points, with their tracks as
  // visibility, when at least sparse_min_track_length of the fused images (those listed
  // in W/stereo/fusion.cfg, so photos held out of the geometry never count) see them
  // and their reprojection error is at most sparse_max_error pixels. Stereo leaves
  // textureless floors, white walls and far backgrounds without confirmed depth
  // (doc/real_scenes.md), where SfM often has features. They skip the isolated-point
  // filter: SfM's track and error tests already confirmed them, and the background they
  // add is sparse by nature. 0 = fused points only, as COLMAP.
  int sparse_min_track_length = 2;
  double sparse_max_error = 2.0;
  // <= 0: DefaultNumThreads() (COLMAP uses -1 for "all").
  int num_threads = -1;

  // Throws fvs::Error("delaunay mesher", ...) naming the bad option.
  void Check() const;
  // The options that shape the mesh (not num_threads), for prepare's fingerprint; "" for
  // the defaults before session 29 (max_proj_dist 20, max_side_spacing_factor 10), the
  // fingerprint of meshes made before the options could be set, so those are meshed
  // again with today's defaults and no others are.
  std::string ToString() const;
};

// The mesher's input, in world coordinates.
struct DelaunayMeshingInput {
  std::vector<Eigen::Vector3d> points;
  // Per point, indices into `cameras` of the images that see it (fused.ply.vis).
  std::vector<std::vector<uint32_t>> visibility;
  // Projection is used for point merging (max_proj_dist), the centre for the rays.
  std::vector<PinholeCamera> cameras;
  // The last num_sparse_points of `points` are SfM points (exempt from the isolated-point
  // filter).
  size_t num_sparse_points = 0;
  // Names of the inputs, for error messages.
  std::string points_subject = "points";
  std::string visibility_subject = "visibility";

  // Throws fvs::Error when sizes do not match, a visibility index is out of range, a
  // point is not finite, a camera is invalid, or there are fewer than 4 points.
  void Check() const;
};

struct DelaunayMeshingStats {
  size_t num_input_points = 0;
  size_t num_sparse_points = 0;     // SfM points among the input points
  size_t num_isolated_points = 0;   // dropped before triangulation
  size_t num_vertices = 0;          // triangulation vertices (after merging)
  size_t num_cells = 0;             // including infinite cells
  size_t num_rays = 0;              // (vertex, image) rays cast
  size_t num_ray_steps = 0;         // facets crossed by all rays
  size_t num_surface_facets = 0;    // before the long-edge filter
  size_t num_spacing_filtered = 0;  // faces dropped by max_side_spacing_factor
  size_t num_faces = 0;             // in the output mesh
  size_t num_mesh_vertices = 0;
  double distance_sigma = 0;
  double max_side_length = 0;  // the long-edge filter's threshold
  double seconds_triangulation = 0;
  double seconds_visibility = 0;
  double seconds_graph = 0;  // graph build + max-flow
  double seconds_extraction = 0;
  double seconds_total = 0;

  std::string Summary() const;
};

// Throws fvs::Error when the input is bad (see DelaunayMeshingInput::Check) or the points
// span no volume (all coplanar or collinear: "degenerate point cloud"). A mesh with no
// faces is a valid result (nothing was found inside); callers that need a surface check
// it. No NaN/Inf in the output.
TriangleMesh DelaunayMeshing(const DelaunayMeshingInput& input,
                             const DelaunayMeshingOptions& options,
                             DelaunayMeshingStats* stats = nullptr);

// Reads W/fused.ply, W/fused.ply.vis and W/sparse into a mesher input. The visibility
// indices of fused.ply.vis are positions in COLMAP's list of registered images of
// W/sparse, which COLMAP 3.8 (mvs::Model::ReadFromCOLMAP, Reconstruction::RegImageIds)
// builds in the order the images appear in images.bin / images.txt (not sorted by id: 3.8
// writes images in hash-map order); this reader keeps that file order. Throws fvs::Error
// on a missing or bad file, an empty cloud, or a vis file that does not match the ply
// (count or image index). Appends the SfM points that options.sparse_min_track_length
// and sparse_max_error admit (no fusion.cfg: every registered image counts as fused).
DelaunayMeshingInput ReadDenseMeshingInput(const std::string& workspace_path,
                                           const DelaunayMeshingOptions& options = {});

// The image ids of <sparse_dir>/images.bin (or images.txt) in file order.
std::vector<uint32_t> ReadImageIdsInFileOrder(const std::string& sparse_dir);

// ReadDenseMeshingInput + DelaunayMeshing + WritePlyMesh(output_path) (binary, atomic).
// Throws fvs::Error (and writes nothing) when the result has no faces.
DelaunayMeshingStats DenseDelaunayMeshing(const std::string& workspace_path,
                                          const std::string& output_path,
                                          const DelaunayMeshingOptions& options);

}  // namespace fvs::mvs
