// The stages of view_synthesis_prepare (see view_synthesis_prepare_command.cc).
#pragma once

#include <set>
#include <string>
#include <vector>

#include "colmap_ext/reconstruction.h"

namespace fvs {

struct PrepareContext {
  std::string image_path;      // absolute
  std::string workspace_path;  // absolute
  std::string matcher = "auto";
  std::string camera_model = "SIMPLE_RADIAL";
  bool single_camera = true;
  int max_image_size = 1600;
  std::string stereo_backend = "auto";
  std::string mesher_backend = "auto";
  int stereo_max_image_size = 0;
  std::set<std::string> holdout;
  int num_threads = -1;
};

// "a.jpg,b.jpg" or the path of a file with one name per line; empty -> empty set.
std::set<std::string> ParseHoldoutList(const std::string& spec);

// Image files (by extension) directly in `folder`, sorted. Throws fvs::Error if none.
std::vector<std::string> ListImageFiles(const std::string& folder);

// True when names look like frames of a video: a common prefix and consecutive numbers.
bool LooksLikeVideoFrames(const std::vector<std::string>& names);

// Writes stereo/patch-match.cfg and stereo/fusion.cfg listing the non-holdout images,
// each with explicit sources (the images sharing most sparse points, holdouts excluded),
// so no evaluation target leaks into the geometry.
void WriteStereoConfigs(const std::string& workspace_path,
                        const std::set<std::string>& holdout, int max_sources = 20);

// COLMAP's image_undistorter crops to the region where every pixel is valid and stops at
// --min_scale 0.2. A distortion estimate that cannot be inverted at the image borders
// (SIMPLE_RADIAL with a strong negative k1, whose r (1 + k1 r^2) folds back) shrinks the
// images to a fifth: the scene stays usable but loses most pixels. One line per camera of
// `undistorted` whose longest side is under half of what max_image_size allows.
std::vector<std::string> ShrunkenUndistortionWarnings(
    const colmap::Reconstruction& sfm, const colmap::Reconstruction& undistorted,
    int max_image_size);

void RunPrepareStages(const PrepareContext& context);

}  // namespace fvs
