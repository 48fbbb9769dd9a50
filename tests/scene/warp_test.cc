// Warping maps against a brute-force reference (unproject to world and project with the
// absolute poses, in long double) on random cameras, near and far from the origin, and
// the numerical edge cases (depth 0 / 1e30, behind, edge-on, extreme focal lengths).
#include "fvs/scene/warp.h"

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
Reference BruteForce(const PinholeCamera& t, double x, double y, double d,
                     const PinholeCamera& s) {
  const LMat Rt = t.R.cast<long double>(), Rs = s.R.cast<long double>();
  const LVec tt = t.t.cast<long double>(), ts = s.t.cast<long double>();
  const LVec xc((x + 0.5L - t.cx) / t.fx * d, (y + 0.5L - t.cy) / t.fy * d, d);
  const LVec world = Rt.transpose() * (xc - tt);
  const LVec xs = Rs * world + ts;
  Reference r;
  r.z = xs.z();
  r.in_front = xs.z() > 0;
  r.u = s.fx * xs.x() / xs.z() + s.cx;
  r.v = s.fy * xs.y() / xs.z() + s.cy;
  return r;
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
  // Source depth: random, then made consistent (within 0.5%) where half the targets land.
  Image source_depth(source.width, source.height, 1);
  for (float& d : source_depth.data) d = static_cast<float>(1 + 10 * u01(rng));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double d = EffectiveDepth(target_depth.at(x, y), 1e9);
      const Reference r = BruteForce(target, x, y, d, source);
      if (r.in_front && r.u >= 0 && r.v >= 0 && r.u < source.width &&
          r.v < source.height && u01(rng) < 0.5) {
        source_depth.at(static_cast<int>(r.u), static_cast<int>(r.v)) =
            static_cast<float>(r.z * (1 + 0.005 * (2 * u01(rng) - 1)));
      }
    }
  }
  const WarpMap map = ComputeWarpMap(target, target_depth, source, source_depth);
  int checked_valid = 0, checked = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const float raw = target_depth.at(x, y);
      const bool surface = raw > 0 && std::isfinite(raw);
      EXPECT_EQ(map.valid_depth.data[i], surface ? 1.f : 0.f);
      const double d = EffectiveDepth(raw, 1e9);
      const Reference r = BruteForce(target, x, y, d, source);
      ASSERT_TRUE(std::isfinite(map.source_xy.data[2 * i]));
      ASSERT_TRUE(std::isfinite(map.source_xy.data[2 * i + 1]));
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
      if (inside) {
        // Nearest pixel, else bilinear between the 4 nearest centres when all are
        // surface.
        const int w_s = source.width, h_s = source.height;
        auto depth_at = [&](int sx, int sy) -> long double {
          return source_depth.at(sx, sy);
        };
        const long double dn = EffectiveDepth(
            source_depth.at(static_cast<int>(r.u), static_cast<int>(r.v)), 1e9);
        const long double margin_n = std::fabs(r.z - dn) - 0.01L * r.z;
        const long double fx = std::clamp(r.u - 0.5L, 0.0L, w_s - 1.0L);
        const long double fy = std::clamp(r.v - 0.5L, 0.0L, h_s - 1.0L);
        const int x0 = std::min(static_cast<int>(fx), w_s - 2);
        const int y0 = std::min(static_cast<int>(fy), h_s - 2);
        const long double ax = fx - x0, ay = fy - y0;
        const long double db =
            (1 - ay) * ((1 - ax) * depth_at(x0, y0) + ax * depth_at(x0 + 1, y0)) +
            ay * ((1 - ax) * depth_at(x0, y0 + 1) + ax * depth_at(x0 + 1, y0 + 1));
        const long double margin_b = std::fabs(r.z - db) - 0.01L * r.z;
        if (std::fabs(margin_n) < 1e-6L * r.z || std::fabs(margin_b) < 1e-6L * r.z)
          continue;
        expected =
            margin_n <= 0 || margin_b <= 0;  // the source depth is all surface here
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

TEST(WarpTest, RejectsMismatchedSizes) {
  const PinholeCamera cam = SimpleCamera(20, 10, 18);
  EXPECT_THROW(ComputeWarpMap(cam, Image(19, 10, 1), cam, Image(20, 10, 1)), Error);
  PinholeCamera bad = cam;
  bad.t.x() = std::nan("");
  EXPECT_THROW(ComputeWarpMap(bad, Image(20, 10, 1), cam, Image(20, 10, 1)), Error);
}

}  // namespace
}  // namespace fvs
