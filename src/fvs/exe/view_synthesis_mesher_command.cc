// colmap view_synthesis_mesher --workspace_path W [--output_path W/meshed-delaunay.ply]
//
// The built-in Delaunay graph-cut mesher (src/fvs/mvs/delaunay.h) on a COLMAP dense
// workspace: W/fused.ply + W/fused.ply.vis + W/sparse (its SfM points too, see
// --DelaunayMeshing.sparse_min_track_length) -> W/meshed-delaunay.ply, with the
// options of COLMAP's delaunay_mesher (--DelaunayMeshing.*, same names; the defaults too
// but max_proj_dist, 40 against COLMAP's 20, measured in mvs/delaunay.h), for the COLMAP
// builds that lack CGAL (Debian's). Bad input: one error line, exit 1, no
// output.
#include <filesystem>
#include <iostream>
#include <string>

#include "colmap_ext/workspace.h"
#include "fvs/controllers/workspace_stages.h"
#include "fvs/exe/command_registry.h"
#include "fvs/exe/stereo_flags.h"
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
  AddDelaunayMeshingFlags(&options, &o);
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
