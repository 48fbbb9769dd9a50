// Warping maps: where each target pixel lands in a source image, given the target depth.
// The one warp of the project: the renderers (render/prepare.h), the trainer's samples
// (train/data.h ComputeTrainingWarp), camera paths and the flicker metric all call it.
// No torch here: the maps are plain float images that the renderers sample with
// SampleBilinear and that the network feeds to grid_sample (GridSampleCoordinates).
//
// For the target pixel centre (x + 0.5, y + 0.5) with depth d, X_t = d K_t^-1 (x, y, 1)
// and X_k = R_rel X_t + t_rel with R_rel = R_k R_t^T, t_rel = t_k - R_rel t_t (the
// relative pose, computed once per source in double precision, so absolute translations
// far from the origin never meet single precision). Source pixel u = fx X/Z + cx, v = fy
// Y/Z + cy.
//
// A target pixel WITH a surface (depth d > 0 and finite, valid_depth = 1) is seen by the
// source (valid_warp = 1) when u lands inside the source image, Z > 0, and |Z - D_k| <=
// occlusion_tolerance * Z, where D_k is the source's own depth at the NEAREST source
// pixel, or, if that fails, the source depth interpolated bilinearly between the 4
// nearest pixel centres when all 4 are surface. Why both: at a depth discontinuity a
// bilinear depth mixes the two surfaces and matches neither (nearest is right there, up
// to half a source pixel from the edge); on a surface seen at a grazing angle the depth
// changes by more than 1% within one source pixel and only the interpolated depth is
// within tolerance. A source pixel without a surface counts as invalid_depth, which no
// real surface matches.
//
// A target pixel WITHOUT a surface (d <= 0 or non-finite, valid_depth = 0) looks at
// something beyond the mesh: sky, a far wall. It is warped at infinity, with the
// rotation alone: X_k = R_rel K_t^-1 (x, y, 1), no translation (parallax vanishes at
// infinity). The source sees it when Z > 0, it lands inside the source image and the
// source has no surface at the nearest source pixel either (a source surface there
// stands in front of the background and occludes it). So the background beyond the mesh
// is blended from the sources like any surface, and only what no source sees even at
// infinity is left to hole filling. (Warping such pixels from a finite stand-in depth,
// as the reference code's 1e9, fails: the point's source Z is 1e9 cos(a_k) / cos(a_t),
// a_k and a_t the angles between the ray and the two optical axes, which matches the
// stand-in source depth 1e9 within 1% only for views less than ~8 degrees apart.)
#pragma once

#include "fvs/geometry/camera.h"
#include "fvs/util/image.h"

namespace fvs {

struct WarpOptions {
  double occlusion_tolerance = 0.01;  // relative; the reference code's 1%
  // What a source pixel without a surface counts as in the occlusion test of a target
  // surface point: far beyond any real surface, so it never matches one.
  double invalid_depth = 1e9;
  // Target pixels without a surface are warped at infinity (above); false: they are
  // invalid (source_xy (-1, -1), valid_warp 0), the fvs_noinfdepth ablation.
  bool at_infinity = true;
  int num_threads = 0;  // <= 0: DefaultNumThreads()
  void Check() const;
};

struct WarpMap {
  // 2 channels: source pixel coordinates (u, v) in COLMAP's convention (pixel (0,0) spans
  // [0,1]^2). Always finite; pixels whose point is behind the source hold (-1, -1).
  Image source_xy;
  Image valid_depth;  // 1 channel, 1 where the target depth was a surface
  Image valid_warp;   // 1 channel, 1 where the source sees the point (see above)
  // 1 channel, camera-frame depth of the point in the source (>= 0); 0 where the target
  // pixel has no surface (the point is at infinity).
  Image source_z;
  int64_t num_valid = 0;
};

// The depth replaced by invalid_depth where it is not a surface (what the occlusion test
// compares with).
double EffectiveDepth(float depth, double invalid_depth);

// Maps for one source. target_depth is 1 channel at the target camera's size;
// source_depth at the source camera's size. Throws fvs::Error on mismatched sizes or
// invalid cameras.
WarpMap ComputeWarpMap(const PinholeCamera& target, const Image& target_depth,
                       const PinholeCamera& source, const Image& source_depth,
                       const WarpOptions& options = {});

// The occlusion test above for a point at camera depth z projecting to (u, v) inside the
// source image.
bool SourceSeesDepth(const Image& source_depth, double u, double v, double z,
                     double tolerance, double invalid_depth);

// The test at infinity: the source has no surface at the nearest pixel to (u, v), which
// lies inside the source image.
bool SourceSeesInfinity(const Image& source_depth, double u, double v);

// grid_sample coordinates for align_corners = false: g = 2 u / W - 1, 2 v / H - 1.
Image GridSampleCoordinates(const WarpMap& map, int source_width, int source_height);

// Bilinear sample of `image` at COLMAP pixel coordinates (u, v) (pixel centres at +0.5),
// writes image.channels values to out. Outside the pixel centres: zero padding as
// grid_sample's default, or the border pixels when clamp_to_border (what a renderer wants
// for a point it knows lies inside the image).
void SampleBilinear(const Image& image, double u, double v, float* out,
                    bool clamp_to_border = false);

// Bicubic (Catmull-Rom, Keys a = -0.5) sample of `image` at COLMAP pixel coordinates,
// the 4x4 pixel centres around (u, v) clamped to the border as SampleBilinear's
// clamp_to_border: it blurs less than bilinear between pixel centres (a target pixel
// rarely lands on a source pixel's centre), at 16 reads instead of 4. At a step edge it
// overshoots by up to 7.4 % of the step; callers clamp.
// Non-finite (u, v) or an empty image give 0.
void SampleBicubic(const Image& image, double u, double v, float* out);

}  // namespace fvs
