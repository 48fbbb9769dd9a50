#include "fvs/controllers/prepare_workspace.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>
#include <vector>

#include "colmap_ext/image_io.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/controllers/photo_import.h"
#include "fvs/controllers/prepare_stages.h"
#include "fvs/controllers/sfm_steps.h"
#include "fvs/controllers/stage_runner.h"
#include "fvs/controllers/workspace_stages.h"
#include "fvs/mvs/patch_match.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "fvs/util/string_util.h"

namespace fvs {
namespace fs = std::filesystem;
namespace {

const char* kWho = "colmap view_synthesis_prepare";

// COLMAP's default (5) fingerprints as before, so a workspace fused with it is not fused
// again.
std::string FusionFingerprint(int min_num_pixels) {
  return min_num_pixels == 5 ? "" : "min_num_pixels=" + std::to_string(min_num_pixels);
}

// Without the face test, as before it existed: a workspace refined then is not refined
// again.
std::string RefinementFingerprint(const mvs::MeshRefinementOptions& refine,
                                  const mvs::FaceConsistencyOptions& consistency) {
  return refine.ToString() +
         (consistency.enabled ? " " + consistency.ToString() : std::string());
}

// One run of the stages on resolved options: absolute paths, the holdout names, the
// photos, and the matcher and backends the installed COLMAP decides.
class WorkspacePreparation {
 public:
  explicit WorkspacePreparation(const PrepareWorkspaceOptions& options)
      : c_(Absolute(options)),
        holdout_(ParseHoldoutList(options.holdout_images)),
        ws_(c_.workspace_path),
        image_path_(c_.image_path) {}

  void Run() {
    CheckPhotos();
    colmap::CreateDirectories(fvs_dir_);
    RemoveAll(tmp_dir_);  // leftovers of a killed run: never trusted
    colmap::CreateDirectories(tmp_dir_);
    ChooseBackends(colmap::ProbeColmap());
    StageRunner stages(Manifest::Load(ws_.ManifestPath(), c_.workspace_path),
                       photos_.needed() ? 12 : 11);
    RunSfmStages(&stages);
    RunDenseStages(&stages);
    RemoveAll(tmp_dir_);
    ReportRegistration(registration_path_, holdout_);
    // Every run, not only the one that measured it: a blurry photo is never silent.
    std::cerr << "Photos: "
              << ReadPhotoQualityReport(PhotoQualityPath(c_.workspace_path)).Summary()
              << "\n";
    std::cerr << "Scene ready: " << c_.workspace_path << "\n";
  }

 private:
  static PrepareWorkspaceOptions Absolute(PrepareWorkspaceOptions o) {
    o.image_path = fs::absolute(o.image_path).lexically_normal().string();
    o.workspace_path = fs::absolute(o.workspace_path).lexically_normal().string();
    return o;
  }

  void CheckPhotos() {
    images_ = ListImageFiles(c_.image_path);
    for (const std::string& name : holdout_) {
      if (!std::binary_search(images_.begin(), images_.end(), name)) {
        throw Error(c_.image_path, "holdout image '" + name + "' is not in this folder");
      }
    }
    if (images_.size() < 3) {
      throw Error(c_.image_path, "only " + std::to_string(images_.size()) +
                                     " images: view synthesis needs at least 3 photos");
    }
    // COLMAP skips a photo it cannot read and aborts later (an empty file made its
    // matcher fail a CHECK): every photo's header is read here, before the workspace is
    // touched.
    photos_ = PlanPhotoImport(c_.image_path, images_);
    if (!photos_.needed()) return;
    // From here on the photos are those COLMAP reads, under their names there.
    image_path_ = fvs_dir_ + "/photos";
    images_.clear();
    for (const PlannedPhoto& p : photos_.photos) images_.push_back(p.name);
    std::set<std::string> holdout;
    for (const std::string& name : holdout_) holdout.insert(photos_.NameOf(name));
    holdout_ = holdout;
  }

  void ChooseBackends(const colmap::ColmapCapabilities& caps) {
    matcher_ = c_.matcher;
    matcher_reason_ = "--Matching.type " + matcher_;
    if (matcher_ == "auto") {
      const MatcherChoice choice = ChooseMatcher(images_, caps.has_cuda);
      matcher_ = choice.type;
      matcher_reason_ = choice.reason;
    }
    builtin_stereo_ =
        c_.stereo_backend == "builtin" || (c_.stereo_backend == "auto" && !caps.has_cuda);
    // auto: ours even where COLMAP has CGAL. It is COLMAP's algorithm plus the SfM
    // points and the stray-point filters, which cover more of the photos and render
    // better on held-out views (doc/real_scenes.md); `colmap` still picks COLMAP's.
    builtin_mesher_ = c_.mesher_backend != "colmap";
    if (c_.stereo_backend == "colmap" && !caps.has_cuda) {
      throw Error(kWho, "--Stereo.backend colmap needs a COLMAP built with CUDA; " +
                            caps.executable + " has none (use builtin or auto)");
    }
    if (c_.mesher_backend == "colmap" && !caps.has_cgal) {
      throw Error(kWho, "--Mesher.backend colmap needs a COLMAP built with CGAL; " +
                            caps.executable + " has none (use builtin or auto)");
    }
    gpu_ = caps.has_cuda ? "1" : "0";
  }

  void RunSfmStages(StageRunner* stages);
  void RunDenseStages(StageRunner* stages);
  void ExtractFeatures();
  void MatchIntoDatabase(const std::string& type);
  void Map();
  void Undistort();
  void Stereo();
  void Fuse();
  void Mesh();

  const PrepareWorkspaceOptions c_;
  std::set<std::string> holdout_;  // names as COLMAP reads them (PlannedPhoto::name)
  const colmap::DenseWorkspace ws_;
  // The folder COLMAP reads the photos from: the user's, or W/fvs/photos where some
  // photo had to be converted (photo_import.h).
  std::string image_path_;
  PhotoImportPlan photos_;
  const std::string fvs_dir_ = ws_.FvsDir();
  const std::string tmp_dir_ = fvs_dir_ + "/tmp";
  const std::string threads_ = std::to_string(c_.num_threads);
  const std::string database_ = c_.workspace_path + "/database.db";
  const std::string sfm_model_ = c_.workspace_path + "/sfm/0";
  const std::string registration_path_ = fvs_dir_ + "/registration.json";
  std::vector<std::string> images_;
  std::string matcher_, matcher_reason_;
  bool builtin_stereo_ = false, builtin_mesher_ = false;
  std::string gpu_ = "0";
};

void WorkspacePreparation::RunSfmStages(StageRunner* stages) {
  if (photos_.needed()) {
    stages->Run("photo_import", {c_.image_path}, "", {image_path_}, [&] {
      std::cerr << "  " << photos_.num_converted() << " of " << photos_.photos.size()
                << " photos turned upright or converted from HEIF into " << image_path_
                << "\n";
      ImportPhotos(photos_, c_.image_path, tmp_dir_ + "/photos");
      MoveIntoPlace(tmp_dir_ + "/photos", image_path_);
    });
  }
  // One camera per device where the photos come from several (single_camera): the
  // fingerprint of a one-device folder is what it was before cameras were counted.
  const size_t cameras = c_.single_camera ? photos_.CameraGroups().size() : 0;
  stages->Run("feature_extraction", {image_path_},
              c_.camera_model + " single=" + std::to_string(c_.single_camera) +
                  " size=" + std::to_string(c_.max_image_size) +
                  (cameras > 1 ? " cameras=" + std::to_string(cameras) : ""),
              {database_}, [&] { ExtractFeatures(); });
  stages->Run("matching", {}, matcher_, {database_}, [&] {
    std::cerr << "  " << matcher_ << " matching: " << matcher_reason_ << "\n";
    MatchIntoDatabase(matcher_);
  });
  stages->Run("mapping", {}, "", {sfm_model_}, [&] { Map(); });
  // Workspaces prepared before the report existed.
  if (!fs::exists(registration_path_)) {
    WriteRegistrationReport(registration_path_, images_, sfm_model_, matcher_, false);
  }
}

void WorkspacePreparation::RunDenseStages(StageRunner* stages) {
  std::string holdout_list;
  for (const std::string& h : holdout_) holdout_list += h + ",";
  stages->Run("undistortion", {},
              "size=" + std::to_string(c_.max_image_size) + " holdout=" + holdout_list,
              {ws_.ImagesDir(), ws_.SparseDir()}, [&] { Undistort(); });
  stages->Run("stereo", {},
              std::string(builtin_stereo_ ? "builtin" : "colmap") +
                  " size=" + std::to_string(c_.stereo_max_image_size) +
                  (builtin_stereo_ ? " " + c_.planar_prior.ToString() : "") +
                  // Only when not 1, so that workspaces prepared before it existed
                  // keep their fingerprint.
                  (builtin_stereo_ && c_.stereo_max_window_scale != 1
                       ? " window_scale=" + std::to_string(c_.stereo_max_window_scale)
                       : ""),
              {ws_.StereoDir() + "/depth_maps"}, [&] { Stereo(); });
  stages->Run("fusion", {}, FusionFingerprint(c_.fusion_min_num_pixels),
              {ws_.FusedPath(), ws_.FusedVisPath()}, [&] { Fuse(); });
  const std::string meshing = c_.meshing.ToString();
  stages->Run("meshing", {},
              std::string(builtin_mesher_ ? "builtin" : "colmap") +
                  (meshing.empty() ? "" : " " + meshing),
              {ws_.DelaunayMeshPath()}, [&] { Mesh(); });
  stages->Run("mesh_refinement", {}, RefinementFingerprint(c_.refine, c_.consistency),
              {fvs_dir_ + "/refinement.json"},
              [&] { RefineProxyMesh(c_.workspace_path, c_.refine, c_.consistency); });
  stages->Run("backdrop", {}, c_.backdrop.ToString(), {fvs_dir_ + "/backdrop.json"},
              [&] { BuildBackdrop(c_.workspace_path, c_.backdrop); });
  stages->Run("depth_cache", {}, "", {ws_.FvsDir() + "/depth"},
              [&] { BuildDepthCache(c_.workspace_path, -1); });
  // Last, so that adding it left the fingerprints of the stages before unchanged.
  stages->Run("photo_quality", {}, c_.photo_quality.ToString(),
              {PhotoQualityPath(c_.workspace_path)}, [&] {
                WritePhotoQualityReport(
                    PhotoQualityPath(c_.workspace_path),
                    MeasurePhotoQuality(c_.workspace_path, c_.photo_quality));
              });
}

void WorkspacePreparation::ExtractFeatures() {
  // A database left by a killed extraction is incomplete: start over.
  const std::string tmp_db = tmp_dir_ + "/database.db";
  RemoveAll(tmp_db);
  std::vector<std::string> args = {"feature_extractor",
                                   "--database_path",
                                   tmp_db,
                                   "--image_path",
                                   image_path_,
                                   "--ImageReader.camera_model",
                                   c_.camera_model,
                                   "--ImageReader.single_camera",
                                   c_.single_camera ? "1" : "0",
                                   "--SiftExtraction.use_gpu",
                                   gpu_,
                                   "--SiftExtraction.max_image_size",
                                   std::to_string(c_.max_image_size),
                                   "--SiftExtraction.num_threads",
                                   threads_};
  const std::vector<std::vector<std::string>> groups = photos_.CameraGroups();
  if (!c_.single_camera || groups.size() == 1) {
    colmap::RunColmap(args);
  } else {
    // Photos of several devices (EXIF make, model, lens, focal length, size): one
    // extraction per device into the same database, each making its own shared camera.
    std::cerr << "  " << groups.size() << " cameras (by EXIF make, model, lens, focal "
              << "length and size): one COLMAP camera each\n";
    const std::string list = tmp_dir_ + "/camera_images.txt";
    args.insert(args.end(), {"--image_list_path", list});
    for (const std::vector<std::string>& group : groups) {
      WriteFileAtomic(list, [&](std::ostream& o) {
        for (const std::string& name : group) o << name << "\n";
      });
      colmap::RunColmap(args);
    }
  }
  MoveIntoPlace(tmp_db, database_);
}

// Matching writes into the database: work on a copy, so a kill leaves what was there
// untouched.
void WorkspacePreparation::MatchIntoDatabase(const std::string& type) {
  const std::string tmp_db = tmp_dir_ + "/database.db";
  fs::copy_file(database_, tmp_db, fs::copy_options::overwrite_existing);
  RunMatcher(type, tmp_db, images_, tmp_dir_ + "/pairs.txt", gpu_, threads_);
  MoveIntoPlace(tmp_db, database_);
}

void WorkspacePreparation::Map() {
  const int total = static_cast<int>(images_.size());
  MappedModel best = MapLargestModel(image_path_, database_, tmp_dir_ + "/sfm", threads_);
  const bool retry = ShouldRetryExhaustive(matcher_, best.registered, total);
  if (retry) {
    std::cerr << "  registered " << best.registered << " of " << total << " images after "
              << matcher_ << " matching: matching every pair and mapping again\n";
    MatchIntoDatabase("exhaustive");
    const MappedModel second =
        MapLargestModel(image_path_, database_, tmp_dir_ + "/sfm_exhaustive", threads_);
    if (second.registered > best.registered) best = second;
  }
  if (best.path.empty() || best.registered < 3) {
    throw Error(image_path_, "SfM registered " + std::to_string(best.registered) +
                                 " of " + std::to_string(total) +
                                 " images: too few for view synthesis (photos need "
                                 "more overlap and texture)");
  }
  std::cerr << "  registered " << best.registered << " of " << total << " images\n";
  WriteRegistrationReport(registration_path_, images_, best.path, matcher_, retry);
  colmap::CreateDirectories(c_.workspace_path + "/sfm");
  MoveIntoPlace(best.path, sfm_model_);
}

void WorkspacePreparation::Undistort() {
  const std::string out = tmp_dir_ + "/undistorted";
  colmap::CreateDirectories(out);
  colmap::RunColmap({"image_undistorter", "--image_path", image_path_, "--input_path",
                     sfm_model_, "--output_path", out, "--output_type", "COLMAP",
                     "--max_image_size", std::to_string(c_.max_image_size)});
  const colmap::Reconstruction rec = colmap::ReadSparseModel(out + "/sparse");
  for (const std::string& w : ShrunkenUndistortionWarnings(
           colmap::ReadSparseModel(sfm_model_), rec, c_.max_image_size)) {
    std::cerr << "WARNING: " << w << "\n";
  }
  colmap::CreateDirectories(ws_.StereoDir());
  MoveIntoPlace(out + "/images", ws_.ImagesDir());
  MoveIntoPlace(out + "/sparse", ws_.SparseDir());
  WriteStereoConfigs(c_.workspace_path, holdout_);
  WriteFileAtomic(fvs_dir_ + "/holdout.txt", [&](std::ostream& o) {
    for (const std::string& h : holdout_) o << h << "\n";
  });
}

void WorkspacePreparation::Stereo() {
  if (builtin_stereo_) {
    // view_synthesis_stereo's defaults, at the size asked for.
    mvs::PatchMatchStereoOptions stereo;
    if (c_.stereo_max_image_size > 0) stereo.max_image_size = c_.stereo_max_image_size;
    stereo.planar_prior = c_.planar_prior;
    stereo.patch_match.max_window_scale = c_.stereo_max_window_scale;
    RunBuiltinStereo(c_.workspace_path, stereo);
    return;
  }
  colmap::RunColmap(
      {"patch_match_stereo", "--workspace_path", c_.workspace_path, "--workspace_format",
       "COLMAP", "--PatchMatchStereo.geom_consistency", "1",
       "--PatchMatchStereo.max_image_size",
       std::to_string(c_.stereo_max_image_size > 0 ? c_.stereo_max_image_size : -1)});
}

void WorkspacePreparation::Fuse() {
  const std::string out = tmp_dir_ + "/fused.ply";
  colmap::RunColmap({"stereo_fusion", "--workspace_path", c_.workspace_path,
                     "--workspace_format", "COLMAP", "--input_type", "geometric",
                     "--output_path", out, "--StereoFusion.num_threads", threads_,
                     "--StereoFusion.min_num_pixels",
                     std::to_string(c_.fusion_min_num_pixels)});
  std::error_code ec;
  if (!fs::exists(out, ec) || fs::file_size(out, ec) < 300) {
    throw Error(ws_.FusedPath(),
                "stereo fusion produced no points (the depth maps are "
                "empty: too little texture or overlap?)");
  }
  MoveIntoPlace(out + ".vis", ws_.FusedVisPath());
  MoveIntoPlace(out, ws_.FusedPath());
}

void WorkspacePreparation::Mesh() {
  if (builtin_mesher_) {
    // view_synthesis_mesher's defaults and output.
    mvs::DelaunayMeshingOptions meshing = c_.meshing;
    meshing.num_threads = c_.num_threads;
    RunBuiltinMesher(c_.workspace_path, ws_.DelaunayMeshPath(), meshing);
    return;
  }
  const std::string out = tmp_dir_ + "/meshed-delaunay.ply";
  const mvs::DelaunayMeshingOptions& m = c_.meshing;
  const auto num = [](double x) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.17g", x);
    return std::string(text);
  };
  colmap::RunColmap({"delaunay_mesher",
                     "--input_path",
                     c_.workspace_path,
                     "--input_type",
                     "dense",
                     "--output_path",
                     out,
                     "--DelaunayMeshing.max_proj_dist",
                     num(m.max_proj_dist),
                     "--DelaunayMeshing.max_depth_dist",
                     num(m.max_depth_dist),
                     "--DelaunayMeshing.visibility_sigma",
                     num(m.visibility_sigma),
                     "--DelaunayMeshing.distance_sigma_factor",
                     num(m.distance_sigma_factor),
                     "--DelaunayMeshing.quality_regularization",
                     num(m.quality_regularization),
                     "--DelaunayMeshing.max_side_length_factor",
                     num(m.max_side_length_factor),
                     "--DelaunayMeshing.max_side_length_percentile",
                     num(m.max_side_length_percentile)});
  MoveIntoPlace(out, ws_.DelaunayMeshPath());
}

}  // namespace

void PrepareWorkspaceOptions::Check() const {
  const std::string who = kWho;
  Require(
      matcher == "auto" || matcher == "exhaustive" || matcher == "sequential", who,
      "--Matching.type must be auto, exhaustive or sequential, not '" + matcher + "'");
  Require(stereo_backend == "auto" || stereo_backend == "colmap" ||
              stereo_backend == "builtin",
          who, "--Stereo.backend must be auto, colmap or builtin");
  Require(mesher_backend == "auto" || mesher_backend == "colmap" ||
              mesher_backend == "builtin",
          who, "--Mesher.backend must be auto, colmap or builtin");
  Require(max_image_size > 0, who, "--max_image_size must be positive");
  Require(stereo_max_image_size >= 0, who, "--Stereo.max_image_size must be >= 0");
  Require(mvs::IsValidWindowScale(stereo_max_window_scale), who,
          "--Stereo.max_window_scale must be 1, 2, 4, 8 or 16");
  Require(fusion_min_num_pixels >= 1, who, "--Fusion.min_num_pixels must be >= 1");
  planar_prior.Check();
  meshing.Check();
  consistency.Check();
  refine.Check();
  photo_quality.Check();
  backdrop.Check();
}

void PrepareWorkspace(const PrepareWorkspaceOptions& options) {
  options.Check();
  WorkspacePreparation(options).Run();
}

}  // namespace fvs
