#include "fvs/controllers/workspace_stages.h"

#include <iostream>

#include "fvs/scene/mesh_coverage.h"
#include "fvs/scene/scene.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/progress.h"

namespace fvs {

void RunBuiltinStereo(const std::string& workspace_path,
                      const mvs::PatchMatchStereoOptions& options) {
  const mvs::PatchMatchStereoSummary summary =
      mvs::RunPatchMatchStereo(workspace_path, options);
  std::cerr << "stereo: " << summary.num_problems << " images, "
            << summary.num_photometric_computed << " photometric and "
            << summary.num_geometric_computed << " geometric maps computed, "
            << summary.num_skipped << " already done, " << summary.num_without_depth_range
            << " without depth range; " << summary.seconds << " s" << std::endl;
  if (summary.planar_prior.empty > 0) {
    // How much of what the geometric pass left empty the planar priors filled.
    std::cerr << "stereo: planar priors filled "
              << 100.0 * summary.planar_prior.filled / summary.planar_prior.empty
              << "% of the " << summary.planar_prior.empty << " empty pixels ("
              << summary.planar_prior.candidates << " had a plane)" << std::endl;
  }
}

void RunBuiltinMesher(const std::string& workspace_path, const std::string& output_path,
                      const mvs::DelaunayMeshingOptions& options) {
  options.Check();
  if constexpr (!mvs::DelaunayMesherAvailable()) {
    throw Error(
        "colmap view_synthesis_mesher",
        "the built-in Delaunay mesher is unavailable: this build has no CGAL or "
        "Boost.Graph (install libcgal-dev and libboost-graph-dev and rebuild), or use "
        "a COLMAP built with CGAL: colmap delaunay_mesher");
  }
#ifdef FVS_HAVE_CGAL
  const mvs::DelaunayMeshingStats stats =
      mvs::DenseDelaunayMeshing(workspace_path, output_path, options);
  std::cout << "Delaunay mesher: " << stats.Summary() << "\n"
            << "Wrote " << output_path << std::endl;
#endif
}

void BuildDepthCache(const std::string& workspace_path, int num_threads) {
  SceneLoadOptions load;
  load.use_depth_cache = true;
  load.num_threads = num_threads;
  Timer timer;
  const Scene scene = Scene::Load(workspace_path, load);
  std::cerr << "depth cache: " << scene.num_views() << " views, "
            << scene.num_depths_computed() << " rendered, "
            << scene.num_views() - scene.num_depths_computed() << " reused, "
            << timer.Seconds() << " s\n";
  const MeshCoverage coverage = MeasureMeshCoverage(scene);
  std::cerr << coverage.Summary() << "\n";
  WriteFileAtomic(scene.workspace_path() + "/fvs/depth/coverage.json",
                  [&](std::ostream& out) { out << coverage.ToJson() << "\n"; });
}

}  // namespace fvs
