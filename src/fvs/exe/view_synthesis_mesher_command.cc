// colmap view_synthesis_mesher --workspace_path W [--output_path W/meshed-delaunay.ply]
//
// The built-in Delaunay graph-cut mesher (src/fvs/mvs/delaunay.h) on a COLMAP dense
// workspace: W/fused.ply + W/fused.ply.vis + W/sparse (its SfM points too, see
// --DelaunayMeshing.sparse_min_track_length) -> W/meshed-delaunay.ply, with the
// options of COLMAP's delaunay_mesher (--DelaunayMeshing.*, same names and defaults), for
// the COLMAP builds that lack CGAL (Debian's). Bad input: one error line, exit 1, no
// output.
#include <filesystem>
#include <iostream>
#include <string>

#include "colmap_ext/workspace.h"
#include "fvs/controllers/workspace_stages.h"
#include "fvs/exe/command_registry.h"
#include "fvs/mvs/delaunay.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;

int RunViewSynthesisMesher(int argc, char** argv) {
  std::string workspace_path;
  std::string output_path;
  mvs::DelaunayMeshingOptions o;
  OptionManager options(
      "view_synthesis_mesher",
      "Delaunay graph-cut meshing (Labatut et al. 2009, as COLMAP's delaunay_mesher) of "
      "W/fused.ply with the visibility in W/fused.ply.vis and the cameras of W/sparse; "
      "writes W/meshed-delaunay.ply.");
  options.AddRequired("workspace_path", &workspace_path,
                      "COLMAP dense workspace with fused.ply, fused.ply.vis and sparse/");
  options.AddDefault("output_path", &output_path,
                     "output mesh (default: <workspace_path>/meshed-delaunay.ply)");
  options.AddDefault("DelaunayMeshing.max_proj_dist", &o.max_proj_dist,
                     "merge points that reproject within this many pixels of a cell's "
                     "vertices in every image that sees them (0: keep all points)");
  options.AddDefault("DelaunayMeshing.max_depth_dist", &o.max_depth_dist,
                     "... and whose relative depth differs by less than this");
  options.AddDefault("DelaunayMeshing.visibility_sigma", &o.visibility_sigma,
                     "points seen by few images weigh less: 1 - exp(-n^2 / (2 sigma^2))");
  options.AddDefault(
      "DelaunayMeshing.distance_sigma_factor", &o.distance_sigma_factor,
      "free-space falloff near a point, times the 25th percentile edge length");
  options.AddDefault("DelaunayMeshing.quality_regularization", &o.quality_regularization,
                     "weight of the surface-quality (smoothness) term");
  options.AddDefault("DelaunayMeshing.max_side_length_factor", &o.max_side_length_factor,
                     "drop faces whose longest side exceeds this factor times ...");
  options.AddDefault("DelaunayMeshing.max_side_length_percentile",
                     &o.max_side_length_percentile,
                     "... this percentile of the faces' longest sides");
  options.AddDefault("DelaunayMeshing.isolated_point_neighbors",
                     &o.isolated_point_neighbors,
                     "not in COLMAP: drop points far from their k nearest points before "
                     "meshing (0: keep all)");
  options.AddDefault("DelaunayMeshing.isolated_point_factor", &o.isolated_point_factor,
                     "... farther than this factor times the median neighbour distance");
  options.AddDefault("DelaunayMeshing.max_side_spacing_factor",
                     &o.max_side_spacing_factor,
                     "not in COLMAP: drop faces longer than this factor times the local "
                     "point spacing at their vertices (0: off)");
  options.AddDefault("DelaunayMeshing.sparse_min_track_length",
                     &o.sparse_min_track_length,
                     "not in COLMAP: add the SfM points seen by at least this many fused "
                     "images (stereo/fusion.cfg; 0: fused points only)");
  options.AddDefault("DelaunayMeshing.sparse_max_error", &o.sparse_max_error,
                     "... whose reprojection error is at most this many pixels");
  options.AddDefault("DelaunayMeshing.num_threads", &o.num_threads,
                     "threads (-1: all cores)");
  if (!options.Parse(argc, argv)) return 0;
  const colmap::DenseWorkspace ws(workspace_path);
  if (output_path.empty()) output_path = ws.DelaunayMeshPath();
  o.Check();
  const FolderLock lock(fs::path(output_path).parent_path().string(),
                        "view_synthesis_mesher");
  if (output_path == ws.DelaunayMeshPath() && fs::exists(ws.RefinedMeshPath())) {
    // A refinement of the mesh being replaced would be rendered instead of the new one.
    std::cerr << "Removing " << ws.RefinedMeshPath()
              << " (it refines the mesh being replaced; view_synthesis_prepare refines "
                 "the new one)\n";
    fs::remove(ws.RefinedMeshPath());
  }

  RunBuiltinMesher(workspace_path, output_path, o);
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_mesher",
                     "Delaunay graph-cut mesh of a dense workspace (built-in, CPU)",
                     RunViewSynthesisMesher);

}  // namespace fvs
