// colmap view_synthesis_depth_cache --workspace_path W: renders the depth of every source
// view from the proxy mesh (W/meshed-refined.ply or W/meshed-delaunay.ply) into
// W/fvs/depth/ (reusing what is current). The last stage of view_synthesis_prepare; on
// its own after a mesh was replaced. Prints how much of the photos the mesh covers and
// writes it per view to W/fvs/depth/coverage.json.
#include <string>

#include "fvs/controllers/workspace_stages.h"
#include "fvs/exe/command_registry.h"
#include "fvs/util/folder_lock.h"
#include "fvs/util/option_manager.h"

namespace fvs {
namespace {

int RunDepthCache(int argc, char** argv) {
  std::string workspace_path;
  int num_threads = -1;
  OptionManager options("view_synthesis_depth_cache",
                        "Render the depth of every source view from the proxy mesh into "
                        "W/fvs/depth/ (COLMAP .bin arrays, 0 = no surface).");
  options.AddRequired("workspace_path", &workspace_path, "dense workspace");
  options.AddDefault("num_threads", &num_threads, "-1 = all cores");
  if (!options.Parse(argc, argv)) return 0;
  const FolderLock lock(workspace_path, "view_synthesis_depth_cache");
  BuildDepthCache(workspace_path, num_threads);
  return 0;
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_depth_cache",
                     "render source depths from the proxy mesh into W/fvs/depth",
                     RunDepthCache);

}  // namespace fvs
