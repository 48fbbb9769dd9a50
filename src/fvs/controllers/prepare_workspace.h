// Preparing a workspace as one call: what `colmap view_synthesis_prepare` runs. Photos ->
// ready scene: feature extraction, matching, mapping, undistortion (COLMAP), dense stereo
// (COLMAP's when it has CUDA, else ours), fusion (COLMAP), meshing (COLMAP's when it has
// CGAL, else ours), mesh refinement (mvs/mesh_refinement.h), backdrop (what lies beyond
// the mesh: scene/backdrop.h), source depth cache, photo quality (blurry and duplicate
// photos: scene/photo_quality.h). HEIC and stored-rotated photos are first written
// upright into W/fvs/photos (photo_import.h). Each stage records a fingerprint of
// its inputs and options in W/fvs/manifest.json and is skipped when that is unchanged and
// its outputs exist. Fingerprints chain (a stage's includes the one before it), so
// changing an early stage re-runs everything after it. Stages write into W/fvs/tmp/ and
// rename into place, so kill -9 at any point loses at most the stage that was running
// (stage_runner.h).
#pragma once

#include <string>

#include "fvs/mvs/delaunay.h"
#include "fvs/mvs/face_consistency.h"
#include "fvs/mvs/mesh_refinement.h"
#include "fvs/mvs/planar_prior.h"
#include "fvs/scene/backdrop.h"
#include "fvs/scene/photo_quality.h"

namespace fvs {

struct PrepareWorkspaceOptions {
  std::string image_path;        // folder of the input photos
  std::string workspace_path;    // the dense workspace made (relative paths are fine)
  std::string matcher = "auto";  // auto | exhaustive | sequential (prepare_stages.h)
  std::string camera_model = "SIMPLE_RADIAL";
  bool single_camera = true;
  int max_image_size = 1600;            // SIFT and undistortion
  std::string stereo_backend = "auto";  // auto | colmap | builtin
  std::string mesher_backend = "auto";  // auto (= builtin) | colmap | builtin
  int stereo_max_image_size = 0;        // 0 = full undistorted size
  // mvs::PatchMatchOptions::max_window_scale of the built-in stereo.
  int stereo_max_window_scale = 1;
  // COLMAP stereo_fusion's --StereoFusion.min_num_pixels: the views whose depth must
  // agree on a point before it is fused.
  int fusion_min_num_pixels = 5;
  // The built-in stereo's fill of textureless and unconfirmed pixels (--PlanarPrior.*).
  mvs::PlanarPriorOptions planar_prior;
  // The Delaunay graph-cut mesher (--DelaunayMeshing.*; num_threads comes from
  // num_threads). The COLMAP backend gets the options COLMAP's delaunay_mesher has.
  mvs::DelaunayMeshingOptions meshing;
  // The mesh refined by photo-consistency: faces the photos contradict removed
  // (--Consistency.*), then vertices moved (--Refine.*, off by default).
  mvs::FaceConsistencyOptions consistency;
  mvs::MeshRefinementOptions refine;
  // What lies beyond the mesh, fitted to the photos before infinity (--Backdrop.*).
  BackdropOptions backdrop;
  // Blurry and near-duplicate photos (--PhotoQuality.*).
  PhotoQualityOptions photo_quality;
  // Registered by SfM but kept out of stereo, fusion and meshing: a file with one image
  // name per line, or a comma-separated list.
  std::string holdout_images;
  int num_threads = -1;

  // Throws fvs::Error with one line naming the option that is wrong.
  void Check() const;
};

// Runs the stages that are not up to date, logging each on stderr, and ends with what SfM
// registered. Checks the photos (at least 3, every one readable, every holdout among
// them) and the backends asked for before the workspace is touched. Throws fvs::Error
// with one line for bad input or a failed stage.
void PrepareWorkspace(const PrepareWorkspaceOptions& options);

}  // namespace fvs
