// Warping maps against a brute-force reference (unproject to world and project with the
// absolute poses, in long double) on random cameras, near and far from the origin, and
// the numerical edge cases (depth 0 / 1e30, behind, edge-on, extreme focal lengths).
#include "fvs/geometry/warp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "fvs/util/error.h"

namespace fvs {
namespace {

using LVec = Eigen::Matrix<long double, 3, 1>;
using LMat = Eigen::Matrix<long double, 3, 3>;

PinholeCamera RandomCamera(std::mt19937& rng, const Eigen::Vector3d& center, int w,
                           int h) {
  std::uniform_real_distribution<double> u(-1, 1);
  PinholeCamera c;
  c.width = w;
  c.height = h;
  c.fx = w * (0.6 + 0.4 * (u(rng) + 1));
  c.fy = c.fx * (1 + 0.05 * u(rng));
  c.cx = 0.5 * w + 2 * u(rng);
  c.cy = 0.5 * h + 2 * u(rng);
  // Small random rotation about a common forward direction so the views overlap.
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  c.R = Eigen::AngleAxisd(0.25 * u(rng), axis).toRotationMatrix();
  c.t = -c.R * center;
  return c;
}

struct Reference {
  long double u, v, z;
  bool in_front;
};

// World point of the target pixel, projected by the absolute source pose, all long
// double.
// A point (or direction) in the source camera frame, projected.
Reference ProjectReference(const LVec& xs, const PinholeCamera& s) {
  Reference r;
  r.z = xs.z();
  r.in_front = xs.z() > 0;
  r.u = s.fx * xs.x() / xs.z() + s.cx;
  r.v = s.fy * xs.y() / xs.z() + s.cy;
  return r;
}

Reference BruteForce(const PinholeCamera& t, double x, double y, double d,
                     const PinholeCamera& s) {
  const LMat Rt = t.R.cast<long double>(), Rs = s.R.cast<long double>();
  const LVec tt = t.t.cast<long double>(), ts = s.t.cast<long double>();
  const LVec xc((x + 0.5L - t.cx) / t.fx * d, (y + 0.5L - t.cy) / t.fy * d, d);
  const LVec world = Rt.transpose() * (xc - tt);
  return ProjectReference(Rs * world + ts, s);
}

// The direction of the target pixel's ray rotated into the source (no translation: a
// point at infinity), projected, all long double.
Reference BruteForceAtInfinity(const PinholeCamera& t, double x, double y,
                               const PinholeCamera& s) {
  const LMat Rt = t.R.cast<long double>(), Rs = s.R.cast<long double>();
  const LVec ray((x + 0.5L - t.cx) / t.fx, (y + 0.5L - t.cy) / t.fy, 1.0L);
  return ProjectReference(Rs * (Rt.transpose() * ray), s);
}

bool IsSurface(float d) { return d > 0 && std::isfinite(d); }

// Whether the reference occlusion test passes for a target surface point at source depth
// r.z landing at (r.u, r.v) inside the source; *ambiguous when it is within rounding of
// the tolerance.
bool ReferenceSeesDepth(const Image& source_depth, const Reference& r, bool* ambiguous) {
  const int w_s = source_depth.width, h_s = source_depth.height;
  auto depth_at = [&](int sx, int sy) -> long double { return source_depth.at(sx, sy); };
  // Nearest pixel, else bilinear between the 4 nearest centres when all are surface.
  const long double dn =
      EffectiveDepth(source_depth.at(static_cast<int>(r.u), static_cast<int>(r.v)), 1e9);
  const long double margin_n = std::fabs(r.z - dn) - 0.01L * r.z;
  const long double fx = std::clamp(r.u - 0.5L, 0.0L, w_s - 1.0L);
  const long double fy = std::clamp(r.v - 0.5L, 0.0L, h_s - 1.0L);
  const int x0 = std::min(static_cast<int>(fx), w_s - 2);
  const int y0 = std::min(static_cast<int>(fy), h_s - 2);
  const long double ax = fx - x0, ay = fy - y0;
  const bool all_surface = IsSurface(source_depth.at(x0, y0)) &&
                           IsSurface(source_depth.at(x0 + 1, y0)) &&
                           IsSurface(source_depth.at(x0, y0 + 1)) &&
                           IsSurface(source_depth.at(x0 + 1, y0 + 1));
  const long double db =
      (1 - ay) * ((1 - ax) * depth_at(x0, y0) + ax * depth_at(x0 + 1, y0)) +
      ay * ((1 - ax) * depth_at(x0, y0 + 1) + ax * depth_at(x0 + 1, y0 + 1));
  const long double margin_b = std::fabs(r.z - db) - 0.01L * r.z;
  *ambiguous = std::fabs(margin_n) < 1e-6L * r.z ||
               (all_surface && std::fabs(margin_b) < 1e-6L * r.z);
  return margin_n <= 0 || (all_surface && margin_b <= 0);
}

void CheckAgainstBruteForce(const Eigen::Vector3d& origin, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  const int w = 48, h = 36;
  const PinholeCamera target = RandomCamera(rng, origin, w, h);
  const PinholeCamera source = RandomCamera(
      rng, origin + Eigen::Vector3d(0.4 * u01(rng), 0.3, -0.2), w + 8, h + 4);
  Image target_depth(w, h, 1);
  for (float& d : target_depth.data) {
    const double r = u01(rng);
    d = r < 0.05   ? 0.f
        : r < 0.08 ? std::numeric_limits<float>::quiet_NaN()
                   : static_cast<float>(2 + 6 * u01(rng));
  }
  // Source depth: random with 10% without a surface (where the target's background is
  // seen at infinity), then made consistent (within 0.5%) where half the target surface
  // points land.
  Image source_depth(source.width, source.height, 1);
  for (float& d : source_depth.data) {
    d = u01(rng) < 0.1 ? 0.f : static_cast<float>(1 + 10 * u01(rng));
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!IsSurface(target_depth.at(x, y))) continue;
      const Reference r = BruteForce(target, x, y, target_depth.at(x, y), source);
      if (r.in_front && r.u >= 0 && r.v >= 0 && r.u < source.width &&
          r.v < source.height && u01(rng) < 0.5) {
        source_depth.at(static_cast<int>(r.u), static_cast<int>(r.v)) =
            static_cast<float>(r.z * (1 + 0.005 * (2 * u01(rng) - 1)));
      }
    }
  }
  const WarpMap map = ComputeWarpMap(target, target_depth, source, source_depth);
  int checked_valid = 0, checked = 0, valid_at_infinity = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const float raw = target_depth.at(x, y);
      const bool surface = IsSurface(raw);
      EXPECT_EQ(map.valid_depth.data[i], surface ? 1.f : 0.f);
      const Reference r = surface ? BruteForce(target, x, y, raw, source)
                                  : BruteForceAtInfinity(target, x, y, source);
      ASSERT_TRUE(std::isfinite(map.source_xy.data[2 * i]));
      ASSERT_TRUE(std::isfinite(map.source_xy.data[2 * i + 1]));
      if (!surface) EXPECT_EQ(map.source_z.data[i], 0.f);
      if (!r.in_front) {
        EXPECT_EQ(map.valid_warp.data[i], 0.f);
        continue;
      }
      // Float output: relative 1e-6 of the coordinate's magnitude.
      const long double tol = 1e-3L + 2e-6L * std::fabs(r.u);
      if (std::fabs(r.u) < 1e6L && std::fabs(r.v) < 1e6L) {
        EXPECT_NEAR(map.source_xy.data[2 * i], static_cast<double>(r.u),
                    static_cast<double>(tol));
        EXPECT_NEAR(map.source_xy.data[2 * i + 1], static_cast<double>(r.v),
                    static_cast<double>(1e-3L + 2e-6L * std::fabs(r.v)));
      }
      const bool inside =
          r.u >= 0 && r.v >= 0 && r.u < source.width && r.v < source.height;
      bool expected = false;
      if (inside && surface) {
        bool ambiguous = false;
        expected = ReferenceSeesDepth(source_depth, r, &ambiguous);
        if (ambiguous) continue;
      } else if (inside) {
        // At infinity: seen where the source has no surface either.
        expected =
            !IsSurface(source_depth.at(static_cast<int>(r.u), static_cast<int>(r.v)));
        valid_at_infinity += expected;
      }
      // Pixels whose projection is a hair from a pixel border are ambiguous.
      const long double fu = r.u - std::floor(r.u), fv = r.v - std::floor(r.v);
      if (fu < 1e-7L || fu > 1 - 1e-7L || fv < 1e-7L || fv > 1 - 1e-7L) continue;
      EXPECT_EQ(map.valid_warp.data[i], expected ? 1.f : 0.f)
          << "pixel " << x << "," << y;
      ++checked;
      checked_valid += expected;
    }
  }
  EXPECT_GT(valid_at_infinity, 0);
  // The test must exercise both outcomes.
  EXPECT_GT(checked_valid, w * h / 10);
  EXPECT_GT(checked - checked_valid, w * h / 20);
}

TEST(WarpTest, MatchesBruteForceNearOrigin) {
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    CheckAgainstBruteForce(Eigen::Vector3d(0.3, -0.2, 0.1), seed);
  }
}

TEST(WarpTest, MatchesBruteForceFarFromOrigin) {
  for (uint32_t seed = 11; seed <= 16; ++seed) {
    CheckAgainstBruteForce(Eigen::Vector3d(1e4, -2e4, 5e3), seed);
  }
}

PinholeCamera SimpleCamera(int w, int h, double f) {
  PinholeCamera c;
  c.width = w;
  c.height = h;
  c.fx = c.fy = f;
  c.cx = 0.5 * w;
  c.cy = 0.5 * h;
  return c;
}

void ExpectFinite(const WarpMap& map) {
  for (const Image* image :
       {&map.source_xy, &map.valid_depth, &map.valid_warp, &map.source_z}) {
    for (float v : image->data) ASSERT_TRUE(std::isfinite(v));
  }
}

TEST(WarpTest, DepthZeroAndHugeEverywhereStayFinite) {
  PinholeCamera target = SimpleCamera(16, 12, 14);
  PinholeCamera source = target;
  source.t = Eigen::Vector3d(-0.5, 0, 0);
  for (float depth : {0.f, 1e30f, std::numeric_limits<float>::infinity(), -3.f}) {
    Image td(16, 12, 1, depth), sd(16, 12, 1, depth);
    const WarpMap map = ComputeWarpMap(target, td, source, sd);
    ExpectFinite(map);
    for (float v : map.valid_depth.data) EXPECT_EQ(v, depth == 1e30f ? 1.f : 0.f);
  }
  // Invalid everywhere in both: the far "sky" matches itself.
  Image zero(16, 12, 1, 0.f);
  const WarpMap sky = ComputeWarpMap(target, zero, source, zero);
  EXPECT_GT(sky.num_valid, 0);
}

// A source 30 degrees to the side, far from the target: far beyond the old 1e9 stand-in
// test's ~8 degrees. The background lands where the rotation alone puts it, whatever the
// translation.
TEST(WarpTest, BackgroundIsWarpedAtInfinityWithTheRotationOnly) {
  const PinholeCamera target = SimpleCamera(40, 30, 36);
  PinholeCamera rotated = target;
  rotated.R = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitY()).toRotationMatrix();
  PinholeCamera moved = rotated;
  moved.t = Eigen::Vector3d(7, -3, 12);
  const Image sky(40, 30, 1, 0.f);
  const WarpMap a = ComputeWarpMap(target, sky, rotated, sky);
  const WarpMap b = ComputeWarpMap(target, sky, moved, sky);
  ExpectFinite(b);
  EXPECT_EQ(a.source_xy.data, b.source_xy.data);
  EXPECT_EQ(a.valid_warp.data, b.valid_warp.data);
  for (float v : b.valid_depth.data) EXPECT_EQ(v, 0.f);
  for (float v : b.source_z.data) EXPECT_EQ(v, 0.f);
  // Target pixel (x, y): its ray rotated into the source, projected.
  int valid = 0, outside = 0;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const Eigen::Vector3d d =
          rotated.R * Eigen::Vector3d((x + 0.5 - 20) / 36, (y + 0.5 - 15) / 36, 1);
      const double u = 36 * d.x() / d.z() + 20, v = 36 * d.y() / d.z() + 15;
      const size_t i = static_cast<size_t>(y) * 40 + x;
      EXPECT_NEAR(b.source_xy.data[2 * i], u, 1e-4);
      EXPECT_NEAR(b.source_xy.data[2 * i + 1], v, 1e-4);
      const bool inside = u >= 0 && v >= 0 && u < 40 && v < 30;
      EXPECT_EQ(b.valid_warp.data[i], inside ? 1.f : 0.f) << x << "," << y;
      valid += inside;
      outside += !inside;
    }
  }
  EXPECT_EQ(b.num_valid, valid);
  EXPECT_GT(valid, 200);    // the half of the target the source looks at
  EXPECT_GT(outside, 200);  // and the rest, outside the source image
}

TEST(WarpTest, SourceSurfaceOccludesTheBackground) {
  const PinholeCamera target = SimpleCamera(40, 30, 36);
  PinholeCamera source = target;
  source.R = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  source.t = Eigen::Vector3d(0.5, 0, 0);
  // The source has a surface in its left half: the background behind it is hidden there.
  Image source_depth(40, 30, 1, 0.f);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 20; ++x) source_depth.at(x, y) = 3.f;
  }
  const WarpMap map = ComputeWarpMap(target, Image(40, 30, 1, 0.f), source, source_depth);
  int hidden = 0, seen = 0;
  for (size_t i = 0; i < map.valid_warp.data.size(); ++i) {
    const double u = map.source_xy.data[2 * i], v = map.source_xy.data[2 * i + 1];
    if (!(u >= 0 && v >= 0 && u < 40 && v < 30)) {
      EXPECT_EQ(map.valid_warp.data[i], 0.f);
      continue;
    }
    const bool behind_surface = static_cast<int>(u) < 20;
    EXPECT_EQ(map.valid_warp.data[i], behind_surface ? 0.f : 1.f);
    hidden += behind_surface;
    seen += !behind_surface;
  }
  EXPECT_GT(hidden, 100);
  EXPECT_GT(seen, 100);
  // Target surface pixels keep the depth test: a point at the source's far side has no
  // source surface to match, so it is not seen (and never "seen at infinity").
  Image near(40, 30, 1, 3.f);
  const WarpMap surface = ComputeWarpMap(target, near, source, source_depth);
  for (size_t i = 0; i < surface.valid_warp.data.size(); ++i) {
    const double u = surface.source_xy.data[2 * i];
    if (u >= 20 && u < 40) EXPECT_EQ(surface.valid_warp.data[i], 0.f);
  }
}

// The fvs_noinfdepth ablation: pixels without a surface are invalid at (-1, -1); those
// with one are warped exactly as with the default.
TEST(WarpTest, WithoutInfinityTheBackgroundIsInvalid) {
  const PinholeCamera target = SimpleCamera(40, 30, 36);
  PinholeCamera source = target;
  source.R = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  source.t = Eigen::Vector3d(0.2, 0, 0);
  Image target_depth(40, 30, 1, 3.f), source_depth(40, 30, 1, 0.f);
  for (int x = 0; x < 40; ++x) {
    for (int y = 0; y < 10; ++y) target_depth.at(x, y) = 0.f;  // sky in the top rows
    for (int y = 10; y < 30; ++y) source_depth.at(x, y) = 3.f;
  }
  WarpOptions no_infinity;
  no_infinity.at_infinity = false;
  const WarpMap with = ComputeWarpMap(target, target_depth, source, source_depth);
  const WarpMap without =
      ComputeWarpMap(target, target_depth, source, source_depth, no_infinity);
  int64_t sky_seen = 0;
  for (size_t i = 0; i < with.valid_warp.data.size(); ++i) {
    if (target_depth.data[i] > 0) {
      EXPECT_EQ(without.source_xy.data[2 * i], with.source_xy.data[2 * i]);
      EXPECT_EQ(without.source_xy.data[2 * i + 1], with.source_xy.data[2 * i + 1]);
      EXPECT_EQ(without.valid_warp.data[i], with.valid_warp.data[i]);
      EXPECT_EQ(without.source_z.data[i], with.source_z.data[i]);
    } else {
      sky_seen += with.valid_warp.data[i] > 0;
      EXPECT_EQ(without.source_xy.data[2 * i], -1.f);
      EXPECT_EQ(without.source_xy.data[2 * i + 1], -1.f);
      EXPECT_EQ(without.valid_warp.data[i], 0.f);
      EXPECT_EQ(without.valid_depth.data[i], 0.f);
    }
  }
  EXPECT_GT(sky_seen, 0);  // the default does see the sky
  EXPECT_EQ(without.num_valid, with.num_valid - sky_seen);
}

TEST(WarpTest, BackgroundAtExtremePosesStaysFinite) {
  const Image sky(12, 10, 1, 0.f);
  for (double f : {1e-3, 14.0, 1e7}) {
    const PinholeCamera target = SimpleCamera(12, 10, f);
    for (double angle : {0.0, M_PI / 2, M_PI / 2 - 1e-12, M_PI, 3.0}) {
      for (double distance : {0.0, 1e-9, 1e12}) {
        PinholeCamera source = target;
        source.R = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 0.5).normalized())
                       .toRotationMatrix();
        source.t = Eigen::Vector3d(distance, -distance, 0.5 * distance);
        const WarpMap map = ComputeWarpMap(target, sky, source, sky);
        ExpectFinite(map);
        // Looking the other way (a wide-angle target still reaches round the side).
        if (angle == M_PI && f == 14.0) EXPECT_EQ(map.num_valid, 0);
      }
    }
  }
}

TEST(WarpTest, TargetBehindSourceAndEdgeOnAreInvalidButFinite) {
  const PinholeCamera target = SimpleCamera(16, 12, 14);
  Image td(16, 12, 1, 3.f), sd(16, 12, 1, 3.f);
  // Source 10 units in front of the target, looking the same way: every point is behind
  // it.
  PinholeCamera behind = target;
  behind.t = Eigen::Vector3d(0, 0, -10);
  WarpMap map = ComputeWarpMap(target, td, behind, sd);
  ExpectFinite(map);
  EXPECT_EQ(map.num_valid, 0);
  // Source whose image plane contains the target's optical axis (seen edge-on).
  PinholeCamera edge = target;
  edge.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  edge.t = -edge.R * Eigen::Vector3d(0, 0, 3);
  map = ComputeWarpMap(target, td, edge, sd);
  ExpectFinite(map);
}

TEST(WarpTest, ExtremeFocalLengthsStayFinite) {
  for (double f : {1e-3, 1e7}) {
    PinholeCamera target = SimpleCamera(10, 8, f);
    PinholeCamera source = target;
    source.t = Eigen::Vector3d(0.2, 0.1, 0);
    Image td(10, 8, 1, 2.f), sd(10, 8, 1, 2.f);
    ExpectFinite(ComputeWarpMap(target, td, source, sd));
  }
}

TEST(WarpTest, IdentityWarpIsValidEverywhere) {
  const PinholeCamera cam = SimpleCamera(20, 10, 18);
  Image depth(20, 10, 1, 4.f);
  const WarpMap map = ComputeWarpMap(cam, depth, cam, depth);
  EXPECT_EQ(map.num_valid, 200);
  EXPECT_NEAR(map.source_xy.at(3, 7, 0), 3.5, 1e-5);
  EXPECT_NEAR(map.source_xy.at(3, 7, 1), 7.5, 1e-5);
  // An occluder 2% in front in the source: rejected at 1%, accepted at 5%.
  Image closer(20, 10, 1, 4.f / 1.02f);
  EXPECT_EQ(ComputeWarpMap(cam, depth, cam, closer).num_valid, 0);
  WarpOptions loose;
  loose.occlusion_tolerance = 0.05;
  EXPECT_EQ(ComputeWarpMap(cam, depth, cam, closer, loose).num_valid, 200);
}

TEST(WarpTest, OcclusionTestAtGrazingSurfacesAndDiscontinuities) {
  // A ramp rising 5% per pixel (a surface seen at a grazing angle): between two pixel
  // centres the nearest depth is 2.5% off, the bilinear one exact.
  Image ramp(8, 1, 1);
  for (int x = 0; x < 8; ++x) ramp.data[x] = static_cast<float>(4.0 * (1 + 0.05 * x));
  const double z = 4.0 * (1 + 0.05 * 2.5);  // at u = 3.0, the edge between pixels 2 and 3
  EXPECT_TRUE(SourceSeesDepth(ramp, 3.0, 0.5, z, 0.01, 1e9));
  EXPECT_FALSE(SourceSeesDepth(ramp, 3.0, 0.5, z * 0.97, 0.01, 1e9));
  // A step from 2 to 10: a point on either side is seen via its nearest pixel.
  Image step(8, 1, 1);
  for (int x = 0; x < 8; ++x) step.data[x] = x < 4 ? 2.f : 10.f;
  EXPECT_TRUE(SourceSeesDepth(step, 3.9, 0.5, 2.0, 0.01, 1e9));
  EXPECT_TRUE(SourceSeesDepth(step, 4.1, 0.5, 10.0, 0.01, 1e9));
  EXPECT_FALSE(SourceSeesDepth(step, 3.9, 0.5, 10.0, 0.01, 1e9));  // occluded
  // Next to a pixel without surface only the nearest test applies.
  step.data[3] = 0.f;
  EXPECT_FALSE(SourceSeesDepth(step, 4.4, 0.5, 9.0, 0.01, 1e9));  // 0.1 * 0 + 0.9 * 10
}

TEST(WarpTest, GridSampleCoordinatesAlignCornersFalse) {
  const PinholeCamera cam = SimpleCamera(20, 10, 18);
  Image depth(20, 10, 1, 4.f);
  const Image grid =
      GridSampleCoordinates(ComputeWarpMap(cam, depth, cam, depth), 20, 10);
  EXPECT_NEAR(grid.at(0, 0, 0), -1.0 + 1.0 / 20, 1e-6);  // first pixel centre
  EXPECT_NEAR(grid.at(19, 9, 1), 1.0 - 1.0 / 10, 1e-6);  // last pixel centre
}

TEST(WarpTest, SampleBilinear) {
  Image image(2, 2, 1);
  image.data = {0.f, 1.f, 2.f, 3.f};
  float out;
  SampleBilinear(image, 0.5, 0.5, &out);
  EXPECT_FLOAT_EQ(out, 0.f);
  SampleBilinear(image, 1.5, 1.5, &out);
  EXPECT_FLOAT_EQ(out, 3.f);
  SampleBilinear(image, 1.0, 1.0, &out);
  EXPECT_FLOAT_EQ(out, 1.5f);
  SampleBilinear(image, -5, 0.5, &out);
  EXPECT_FLOAT_EQ(out, 0.f);
  // Half a pixel beyond the last centre: half of it (zero padding, as grid_sample).
  SampleBilinear(image, 2.0, 0.5, &out);
  EXPECT_FLOAT_EQ(out, 0.5f);
  // Clamped to the border pixels instead.
  SampleBilinear(image, 2.0, 0.5, &out, true);
  EXPECT_FLOAT_EQ(out, 1.f);
  SampleBilinear(image, 0.0, 0.0, &out, true);
  EXPECT_FLOAT_EQ(out, 0.f);
}

TEST(WarpTest, SampleBicubic) {
  // A quadratic along x (two channels: x^2 and 10 - x) is reproduced exactly between
  // interior pixel centres, which bilinear cannot do for the square.
  Image image(8, 3, 2);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 8; ++x) {
      image.at(x, y, 0) = static_cast<float>(x * x);
      image.at(x, y, 1) = static_cast<float>(10 - x);
    }
  }
  float out[2];
  for (const double x : {1.0, 2.25, 3.5, 4.8, 5.0}) {
    SampleBicubic(image, x + 0.5, 1.5, out);
    EXPECT_NEAR(out[0], x * x, 1e-4) << x;
    EXPECT_NEAR(out[1], 10 - x, 1e-5) << x;
    float linear[2];
    SampleBilinear(image, x + 0.5, 1.5, linear);
    if (x != std::floor(x)) EXPECT_GT(linear[0], x * x + 0.01) << x;
  }
  // Outside the centres: the border, as SampleBilinear's clamp_to_border.
  SampleBicubic(image, -3.0, 1.5, out);
  EXPECT_FLOAT_EQ(out[0], 0.f);
  SampleBicubic(image, 100.0, -7.0, out);
  EXPECT_FLOAT_EQ(out[0], 49.f);
  EXPECT_FLOAT_EQ(out[1], 3.f);
  // Non-finite coordinates and an empty image give 0, never NaN.
  SampleBicubic(image, std::nan(""), 1.5, out);
  EXPECT_EQ(out[0], 0.f);
  SampleBicubic(image, 1.5, std::numeric_limits<double>::infinity(), out);
  EXPECT_EQ(out[1], 0.f);
  SampleBicubic(Image(), 0.5, 0.5, out);
  // A step edge overshoots by at most 7.4 % of the step (Catmull-Rom's 2 / 27: callers
  // clamp to [0, 1]).
  Image step(6, 1, 1);
  step.data = {0.f, 0.f, 0.f, 1.f, 1.f, 1.f};
  for (double u = 0.5; u <= 5.5; u += 0.125) {
    float v;
    SampleBicubic(step, u, 0.5, &v);
    EXPECT_GE(v, -0.075f);
    EXPECT_LE(v, 1.075f);
  }
}

TEST(WarpTest, RejectsMismatchedSizes) {
  const PinholeCamera cam = SimpleCamera(20, 10, 18);
  EXPECT_THROW(ComputeWarpMap(cam, Image(19, 10, 1), cam, Image(20, 10, 1)), Error);
  PinholeCamera bad = cam;
  bad.t.x() = std::nan("");
  EXPECT_THROW(ComputeWarpMap(bad, Image(20, 10, 1), cam, Image(20, 10, 1)), Error);
}

}  // namespace
}  // namespace fvs
