// The decisions of view_synthesis_prepare's stages (prepare_workspace.h) that do not
// need COLMAP: which photos and holdouts, which matcher and pairs, when to retry, the
// stereo configurations and the check of what undistortion made.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "colmap_ext/reconstruction.h"

namespace fvs {

// "a.jpg,b.jpg" or the path of a file with one name per line; empty -> empty set.
std::set<std::string> ParseHoldoutList(const std::string& spec);

// Image files (by extension) directly in `folder`, sorted. Throws fvs::Error if none.
std::vector<std::string> ListImageFiles(const std::string& folder);

// True when names look like frames of a video: a common prefix and consecutive numbers.
bool LooksLikeVideoFrames(const std::vector<std::string>& names);

// Up to this many photos --Matching.type auto matches every pair (exhaustive), whatever
// the names: n (n - 1) / 2 pairs, 19,900 at 200. On a CPU that many pairs cost about as
// much as CPU stereo on the same photos, and COLMAP's GPU matcher is far faster
// (doc/pipeline.md, Matching, has the figures).
constexpr int kMaxExhaustiveImages = 200;
constexpr int kMaxExhaustiveImagesGpu = 1000;

struct MatcherChoice {
  std::string type;    // "exhaustive" or "sequential"
  std::string reason;  // for the log
};

// The rule of --Matching.type auto: exhaustive up to kMaxExhaustiveImages photos
// (kMaxExhaustiveImagesGpu when SIFT matches on a GPU), numbered or not (name order is
// no evidence of a video); beyond that, sequential with loop closure for frames of a
// video (LooksLikeVideoFrames), and still exhaustive for unordered photos (nothing
// cheaper registers them without a vocabulary tree).
MatcherChoice ChooseMatcher(const std::vector<std::string>& names, bool gpu);

// The image pairs of sequential matching with loop closure, in name order: each frame
// with the next `overlap` and with those 2^k after it (COLMAP's quadratic overlap), and
// every pair of keyframes (every max(5, ceil(n / 50))-th frame, at most about 50 of
// them), which closes loops where the camera comes back. Each pair once, i < j.
std::vector<std::pair<int, int>> SequentialPairs(int num_images, int overlap = 10);

// More thorough matching is worth one retry: mapping registered fewer photos than it
// was given after a matcher that did not try every pair.
bool ShouldRetryExhaustive(const std::string& matcher, int registered, int total);

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

}  // namespace fvs
