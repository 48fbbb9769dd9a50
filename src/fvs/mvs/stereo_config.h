// What the stereo stage computes, in COLMAP 3.8's own terms: stereo/patch-match.cfg
// (pairs of lines: a reference image name, then "__auto__, N", "__all__" or a
// comma-separated list of source image names) and stereo/fusion.cfg (one image name per
// line), plus the choices COLMAP makes from the sparse model: source views (__auto__:
// most shared 3D points with a sufficient triangulation angle) and per-image depth ranges
// (percentiles of the sparse points' depths, with a margin).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "colmap_ext/reconstruction.h"

namespace fvs::mvs {

struct StereoProblem {
  uint32_t ref_image_id = 0;
  std::vector<uint32_t> source_image_ids;  // best first
};

// Sources of `image_id` ranked as COLMAP's __auto__ does: images sharing the most 3D
// points whose triangulation angle (between the two viewing rays) is at least
// min_triangulation_angle degrees. At most max_num_sources.
std::vector<uint32_t> SelectSourceImages(const colmap::Reconstruction& reconstruction,
                                         uint32_t image_id, int max_num_sources,
                                         double min_triangulation_angle);

// Depth range of an image from the camera-frame depths of the sparse points it observes
// (1st and 99th percentile, widened by 25% as COLMAP does); when it observes fewer than
// 3, from all points in front of it that project into it. False when there is nothing to
// go on.
bool ComputeDepthRange(const colmap::Reconstruction& reconstruction, uint32_t image_id,
                       double* depth_min, double* depth_max);

// Parses patch-match.cfg. Names must be images of the model; throws fvs::Error naming the
// file and line otherwise. __auto__ uses SelectSourceImages.
std::vector<StereoProblem> ReadPatchMatchConfig(
    const std::string& path, const colmap::Reconstruction& reconstruction,
    double min_triangulation_angle);

// Writes stereo/patch-match.cfg ("__auto__, 20" for every image) and stereo/fusion.cfg
// (every image) when they do not exist, as image_undistorter does. Atomic.
void WriteDefaultStereoConfigs(const std::string& stereo_dir,
                               const colmap::Reconstruction& reconstruction);

}  // namespace fvs::mvs
