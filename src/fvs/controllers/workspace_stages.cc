#include "fvs/controllers/workspace_stages.h"

#include <filesystem>
#include <iostream>

#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/controllers/prepare_stages.h"
#include "fvs/controllers/stage_runner.h"
#include "fvs/geometry/ply.h"
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

void BuildBackdrop(const std::string& workspace_path, const BackdropOptions& options) {
  options.Check();
  Timer timer;
  const colmap::DenseWorkspace ws(workspace_path);
  const std::string ply = ws.FvsDir() + "/backdrop.ply";
  BackdropFit fit;
  if (options.enabled) {
    const std::string holdout_file = ws.FvsDir() + "/holdout.txt";
    const std::set<std::string> holdout = std::filesystem::exists(holdout_file)
                                              ? ParseHoldoutList(holdout_file)
                                              : std::set<std::string>();
    const colmap::Reconstruction rec = colmap::ReadSparseModel(ws.SparseDir());
    std::vector<BackdropView> views;
    for (const auto& [image_id, image] : rec.images) {
      if (holdout.count(image.name)) continue;  // never seen by the geometry
      BackdropView v;
      v.camera = rec.PinholeFor(image_id);
      v.photo = colmap::ReadImage(ws.ImagePath(image.name), 3);
      views.push_back(std::move(v));
    }
    const TriangleMesh mesh = ReadPlyMesh(ws.DelaunayMeshPath());
    fit = FitBackdrop(views, mesh, options);
  }
  if (fit.mesh.faces.empty()) {
    RemoveAll(ply);
  } else {
    PlyWriteOptions write;
    write.double_precision = true;  // a scene far from the origin
    WritePlyMesh(ply, fit.mesh, write);
  }
  std::cerr << (options.enabled ? fit.Summary() : "backdrop: off") << "; "
            << timer.Seconds() << " s\n";
  WriteFileAtomic(ws.FvsDir() + "/backdrop.json", [&](std::ostream& out) {
    out << "{\"enabled\": " << (options.enabled ? "true" : "false")
        << ", \"directions\": " << fit.num_directions << ", \"finite\": " << fit.num_finite
        << ", \"infinity\": " << fit.num_infinity
        << ", \"unexplained\": " << fit.num_unexplained
        << ", \"unseen\": " << fit.num_unseen << ", \"faces\": " << fit.mesh.faces.size()
        << ", \"options\": \"" << options.ToString() << "\"}\n";
  });
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
