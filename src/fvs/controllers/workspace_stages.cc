#include "fvs/controllers/workspace_stages.h"

#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/controllers/stage_runner.h"
#include "fvs/eval/protocol.h"
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

namespace {

// The photos of W that are not held out, with their cameras (world frame).
template <typename View>
std::vector<View> ReadGeometryPhotos(const colmap::DenseWorkspace& ws) {
  const std::set<std::string> holdout = eval::ReadHoldoutNames(ws.root);
  const colmap::Reconstruction rec = colmap::ReadSparseModel(ws.SparseDir());
  std::vector<View> views;
  for (const auto& [image_id, image] : rec.images) {
    if (holdout.count(image.name)) continue;  // never seen by the geometry
    View v;
    v.camera = rec.PinholeFor(image_id);
    v.photo = colmap::ReadImage(ws.ImagePath(image.name), 3);
    views.push_back(std::move(v));
  }
  return views;
}

}  // namespace

void RefineProxyMesh(const std::string& workspace_path,
                     const mvs::MeshRefinementOptions& options,
                     const mvs::FaceConsistencyOptions& consistency) {
  options.Check();
  consistency.Check();
  const colmap::DenseWorkspace ws(workspace_path);
  nlohmann::json json;
  json["enabled"] = options.enabled;
  json["options"] = options.ToString();
  json["consistency"] = consistency.ToString();
  if (!options.enabled && !consistency.enabled) {
    RemoveAll(ws.RefinedMeshPath());
    std::cerr << "mesh refinement: off\n";
  } else {
    TriangleMesh mesh = ReadPlyMesh(ws.DelaunayMeshPath());
    const auto views = ReadGeometryPhotos<mvs::MeshRefinementView>(ws);
    if (consistency.enabled) {
      mvs::FaceConsistencyResult removed =
          mvs::RemoveInconsistentFaces(views, mesh, consistency);
      std::cerr << removed.Summary() << "; " << removed.seconds << " s\n";
      json["faces_removed"] = removed.num_removed;
      json["faces_judged"] = removed.num_judged;
      json["removed_share"] = removed.removed_area_share;
      json["consistency_seconds"] = removed.seconds;
      mesh = std::move(removed.mesh);
    }
    if (options.enabled) {
      const mvs::MeshRefinementResult result = mvs::RefineMesh(views, mesh, options);
      std::cerr << result.Summary() << "; " << result.seconds << " s\n";
      json["iterations"] = result.num_iterations_run;
      json["stopped_at_time_bound"] = result.stopped_at_time_bound;
      json["data_share"] = {result.first_data_share, result.last_data_share};
      json["ncc"] = {result.ncc_before, result.ncc_after};
      json["median_move_pixels"] = result.median_move_pixels;
      json["seconds"] = result.seconds;
      mesh = result.mesh;
    }
    PlyWriteOptions write;
    write.double_precision = true;  // a scene far from the origin
    WritePlyMesh(ws.RefinedMeshPath(), mesh, write);
  }
  WriteFileAtomic(ws.FvsDir() + "/refinement.json",
                  [&](std::ostream& out) { out << json.dump(2) << "\n"; });
}

void BuildBackdrop(const std::string& workspace_path, const BackdropOptions& options) {
  options.Check();
  Timer timer;
  const colmap::DenseWorkspace ws(workspace_path);
  const std::string ply = ws.FvsDir() + "/backdrop.ply";
  BackdropFit fit;
  if (options.enabled) {
    const auto views = ReadGeometryPhotos<BackdropView>(ws);
    const TriangleMesh mesh = ReadPlyMesh(ws.PreparedMeshPath());
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
  nlohmann::json json;
  json["enabled"] = options.enabled;
  json["directions"] = fit.num_directions;
  json["finite"] = fit.num_finite;
  json["infinity"] = fit.num_infinity;
  json["unexplained"] = fit.num_unexplained;
  json["unseen"] = fit.num_unseen;
  json["faces"] = fit.mesh.faces.size();
  json["options"] = options.ToString();
  WriteFileAtomic(ws.FvsDir() + "/backdrop.json",
                  [&](std::ostream& out) { out << json.dump(2) << "\n"; });
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
