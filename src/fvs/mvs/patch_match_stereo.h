// The stereo stage on a COLMAP dense workspace (as image_undistorter writes it): reads
// W/images, W/sparse (PINHOLE cameras) and W/stereo/patch-match.cfg, runs PatchMatch
// (patch_match.h) photometrically for every reference image, then geometrically against
// the sources' photometric maps, and writes W/stereo/{depth_maps,normal_maps}/<name>.
// {photometric,geometric}.bin in COLMAP's format, so that `colmap stereo_fusion
// --input_type geometric` fuses them unchanged. Images whose outputs exist are skipped
// (the stage can be killed and rerun) unless `overwrite`.
#pragma once

#include <string>

#include "fvs/mvs/patch_match.h"
#include "fvs/mvs/planar_prior.h"
#include "fvs/util/image.h"

namespace fvs::mvs {

struct PatchMatchStereoOptions {
  PatchMatchOptions patch_match;
  // Largest image side used for stereo (0 = full size); maps are written at that size, as
  // COLMAP does (stereo_fusion rescales).
  int max_image_size = 0;
  // Sources scored per pixel: the best-ranked of the configuration's list (the CPU cost
  // grows linearly with it).
  int max_num_sources = 5;
  // __auto__ source selection: minimum triangulation angle (degrees) of a shared point.
  double min_triangulation_angle = 1.0;
  // Run the geometric-consistency pass and write *.geometric.bin.
  bool geom_consistency = true;
  // After the geometric pass: fill what it left empty from planar priors
  // (planar_prior.h). Geometric maps computed with other settings than these (recorded in
  // W/stereo/fvs_geometric_options.txt; a workspace without that file predates it) are
  // deleted and computed again; photometric maps are kept.
  PlanarPriorOptions planar_prior;
  bool overwrite = false;

  void Check() const;  // throws fvs::Error("PatchMatchStereo", ...)
};

struct PatchMatchStereoSummary {
  int num_problems = 0;  // reference images in patch-match.cfg
  int num_photometric_computed = 0;
  int num_geometric_computed = 0;
  int num_skipped = 0;              // reference images whose outputs already existed
  int num_without_depth_range = 0;  // skipped: no sparse point to bound their depth
  PlanarPriorStats planar_prior;    // summed over the geometric maps computed
  double seconds = 0;
};

// The settings the geometric maps depend on, as text (the stamp above).
std::string GeometricOptionsStamp(const PatchMatchStereoOptions& options);

// Throws fvs::Error with one line for a workspace without images or sparse model, fewer
// than two images, a missing image file, a camera that is not pinhole or an image whose
// size does not match its camera.
PatchMatchStereoSummary RunPatchMatchStereo(const std::string& workspace_path,
                                            const PatchMatchStereoOptions& options);

}  // namespace fvs::mvs
