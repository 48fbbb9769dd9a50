// CPU PatchMatch multi-view stereo for one reference view (Schönberger et al., ECCV 2016,
// simplified): per pixel a plane (depth + normal) in the reference camera frame, found by
// random initialisation, red-black checkerboard propagation and random refinement, scored
// by 1 - NCC over a sparse window warped into the source views by the plane's homography
// and aggregated over the best few sources (occluded sources drop out). A second,
// geometric pass adds the forward-backward reprojection error against the sources'
// photometric depth maps; a filter then keeps only pixels that enough sources confirm.
//
// Everything here works on in-memory views; the COLMAP workspace around it lives in
// patch_match_stereo.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs::mvs {

struct PatchMatchOptions {
  // Window of (2 * window_radius + 1)^2 pixels, sampled every window_step pixels. A small
  // window fattens occluding edges least: on the synthetic room (320x240) radius 3
  // step 1 gave 82% of textured pixels within 1%, radius 5 step 2 70%, radius 7 step 2
  // 63%. Radius 3 step 2 (16 samples instead of 49) halves the time for under a point
  // of accuracy on the generated room, in the geometric pass, at 400x300 and at 800x600
  // (patch_match_benchmark; benchmark/README_patch_match.md has the figures).
  int window_radius = 3;
  int window_step = 2;
  // Photometric iterations (each one sweeps both checkerboard colours).
  int num_iterations = 4;
  // Iterations of the geometric-consistency pass (0 = no geometric pass).
  int num_geometric_iterations = 2;
  // The per-pixel cost is the mean of the best `top_k` source costs (2 beat 1 and 3 on
  // the synthetic room: occluded sources drop out, one lucky source does not decide).
  int top_k = 2;
  // Bilateral window weights (as COLMAP): a sample counts exp(-dist^2 / (2
  // sigma_spatial^2)
  // - grey_diff^2 / (2 sigma_color^2)) with dist and grey_diff to the centre pixel, so a
  // window straddling an object edge is dominated by the centre's side. sigma_color <= 0:
  // uniform weights; sigma_spatial <= 0: window_radius.
  double sigma_color = 0.2;
  double sigma_spatial = 0;
  // Pixels whose reference window has a grey standard deviation below this are
  // textureless: NCC says nothing there, so they get no depth.
  double min_texture_std = 0.01;
  // A pixel whose window is textureless tries the same window spread over 2x, 4x, ...
  // up to this many times the area's side (a power of two; 1 = never), same number of
  // samples: the centre of a plain tile reaches the grout around it. The widened window
  // still scores a plane through the pixel, which is what a plain wall or floor is.
  // Off by default (doc/real_scenes.md, session 31): 8 raised the tuning scenes' mesh
  // coverage by 3-5 points, but the report scenes lost PSNR (the temple's column gaps
  // take the columns' depth).
  int max_window_scale = 1;
  // Relative depth perturbation of the first refinement (halved every iteration).
  double depth_perturbation = 0.05;
  // Normal perturbation (radians-ish, added to the unit normal) of the first refinement.
  double normal_perturbation = 0.5;
  // Geometric pass: cost += regularizer * min(reprojection error [px], max_cost).
  double geom_consistency_regularizer = 0.3;
  double geom_consistency_max_cost = 3.0;
  // Filter: a source confirms a pixel when its NCC >= filter_min_ncc, the triangulation
  // angle >= filter_min_triangulation_angle (degrees) and (geometric pass) the
  // reprojection error <= filter_geom_consistency_max_cost pixels. The angle is 1 degree
  // (COLMAP: 3) because the forward-backward check already rejects what a narrow
  // baseline gets wrong; on the synthetic room 3 degrees deleted 19% of textured pixels,
  // most of them correct (1 degree: 8.5%, and more pixels within 1%).
  bool filter = true;
  double filter_min_ncc = 0.1;
  double filter_min_triangulation_angle = 1.0;
  double filter_geom_consistency_max_cost = 1.0;
  // One confirming source (COLMAP: 2): the parts of a view that only one source sees
  // (image borders, the ends of a camera path) would otherwise all be deleted. On the
  // synthetic room 2 (with an adaptive variant: at most the number of sources whose
  // image holds the point) kept 1.3% fewer good pixels and deleted 15% instead of 8.6%.
  int filter_min_num_consistent = 1;
  // Coarse-to-fine: solve at half resolution first (recursively, this many levels, while
  // the smaller side stays >= 64 pixels), then refine the upsampled planes with
  // num_fine_iterations at full resolution. Photometric pass only.
  int num_coarse_levels = 1;
  int num_fine_iterations = 2;
  // Iterations that start from converged planes (finer level, geometric pass) propagate
  // from the 4 nearest neighbours only and skip the random plane: about a third less
  // work there.
  bool fast_refinement = true;
  int num_threads = 0;  // <= 0: DefaultNumThreads()
  uint64_t seed = 0;

  // Throws fvs::Error("PatchMatchStereo", ...) for values out of range.
  void Check() const;
};

// Whether `scale` is a PatchMatchOptions::max_window_scale: 1, 2, 4, 8 or 16.
bool IsValidWindowScale(int scale);

// One view at the working resolution.
struct StereoView {
  std::string name;
  PinholeCamera camera;
  Image grey;  // 1 channel, [0, 1], camera.width x camera.height
  double depth_min = 0;
  double depth_max = 0;
};

struct DepthNormalMap {
  Image depth;   // 1 channel, camera-frame z, 0 = no depth
  Image normal;  // 3 channels, unit, camera frame, facing the camera; 0 where no depth
  Image cost;    // 1 channel, aggregated cost of the pixel's plane (2 where no depth)
};

// Runs PatchMatch for views[ref] against views[sources]. Photometric when source_depths
// is null; geometric when it holds one depth map per source (the sources' photometric
// maps, at the sources' working resolution), starting from `init` (the reference's
// photometric map). Filtering (options.filter) is applied to the result. Throws
// fvs::Error on inconsistent input (sizes, empty source list, bad depth range).
DepthNormalMap PatchMatchView(const std::vector<StereoView>& views, int ref,
                              const std::vector<int>& sources,
                              const PatchMatchOptions& options,
                              const std::vector<const Image*>* source_depths = nullptr,
                              const DepthNormalMap* init = nullptr);

// The plane-induced homography from reference pixel coordinates to source pixel
// coordinates (COLMAP convention, pixel centres at +0.5) for the plane n . X = n . (depth
// * ray(u, v)) in the reference camera frame. Exposed for tests.
Eigen::Matrix3d PlaneHomography(const PinholeCamera& ref, const PinholeCamera& src,
                                const Eigen::Vector3d& normal, double u, double v,
                                double depth);

// Box-filter (area-weighted) downscaling of a 1-channel image to (width, height).
Image DownscaleGrey(const Image& grey, int width, int height);

}  // namespace fvs::mvs
