#include "fvs/geometry/camera.h"

#include <gtest/gtest.h>

#include <random>

#include "geometry/geometry_test_util.h"

namespace fvs {
namespace {

PinholeCamera RandomCamera(std::mt19937& rng, const Eigen::Vector3d& offset) {
  std::uniform_real_distribution<double> u(-1, 1);
  PinholeCamera c;
  c.width = 640;
  c.height = 480;
  c.fx = 500 + 100 * u(rng);
  c.fy = 510 + 100 * u(rng);
  c.cx = 320 + 10 * u(rng);
  c.cy = 240 + 10 * u(rng);
  c.R = QuaternionToRotation(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)));
  const Eigen::Vector3d center = offset + Eigen::Vector3d(u(rng), u(rng), u(rng));
  c.t = -c.R * center;
  return c;
}

TEST(CameraTest, ProjectionAndUnprojectionRoundTrip) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1e4, 1e4, 1e4)}) {
    for (int trial = 0; trial < 50; ++trial) {
      const PinholeCamera c = RandomCamera(rng, offset);
      ASSERT_TRUE(c.IsValid());
      const double px = c.width * u(rng), py = c.height * u(rng),
                   depth = 0.1 + 20 * u(rng);
      const Eigen::Vector3d world = c.Unproject(px, py, depth);
      const Eigen::Vector3d cam = c.WorldToCamera(world);
      EXPECT_NEAR(cam.z(), depth, 1e-12 * (1 + offset.norm()));
      const Eigen::Vector2d pixel = c.CameraToPixel(cam);
      // Far from the origin the world point itself carries ~1e-12 absolute rounding.
      EXPECT_NEAR(pixel.x(), px, 1e-9 * (1 + offset.norm() / depth));
      EXPECT_NEAR(pixel.y(), py, 1e-9 * (1 + offset.norm() / depth));
      EXPECT_LT((c.CameraToWorld(cam) - world).norm(), 1e-11 * (1 + offset.norm()));
      EXPECT_LT((c.Center() - c.CameraToWorld(Eigen::Vector3d::Zero())).norm(),
                1e-11 * (1 + offset.norm()));
      EXPECT_NEAR(c.ViewDirection().dot(world - c.Center()), depth,
                  1e-9 * (1 + offset.norm()));
    }
  }
}

TEST(CameraTest, PixelConventionIsColmaps) {
  PinholeCamera c = testing::CenteredCamera(4, 2, 1);
  // The principal point at the image centre is the corner shared by the four middle
  // pixels.
  EXPECT_EQ(c.CameraToPixel({0, 0, 1}), Eigen::Vector2d(2, 1));
  // The centre of pixel (0, 0) is (0.5, 0.5).
  EXPECT_EQ(c.PixelToCamera(0.5, 0.5, 2), Eigen::Vector3d(-3, -1, 2));
}

TEST(CameraTest, QuaternionsRoundTripWithCanonicalSign) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n;
  for (int i = 0; i < 100; ++i) {
    Eigen::Vector4d q(n(rng), n(rng), n(rng), n(rng));
    q.normalize();
    const Eigen::Matrix3d R = QuaternionToRotation(q);
    EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    const Eigen::Vector4d back = RotationToQuaternion(R);
    EXPECT_GE(back[0], 0);
    EXPECT_LT((back - (q[0] < 0 ? -q : q)).norm(), 1e-12);
  }
}

TEST(CameraTest, ResizedScalesIntrinsics) {
  std::mt19937 rng(5);
  const PinholeCamera c = RandomCamera(rng, Eigen::Vector3d::Zero());
  const PinholeCamera half = c.Resized(320, 240);
  // The same world point lands at half the pixel coordinates (corners scale, not
  // centres).
  const Eigen::Vector3d x = c.Unproject(100.25, 50.5, 3.0);
  const Eigen::Vector2d p = half.CameraToPixel(half.WorldToCamera(x));
  EXPECT_NEAR(p.x(), 50.125, 1e-9);
  EXPECT_NEAR(p.y(), 25.25, 1e-9);
}

TEST(CameraTest, IsValidRejectsBrokenCameras) {
  std::mt19937 rng(6);
  const PinholeCamera good = RandomCamera(rng, Eigen::Vector3d::Zero());
  ASSERT_TRUE(good.IsValid());
  PinholeCamera c = good;
  c.width = 0;
  EXPECT_FALSE(c.IsValid());
  c = good;
  c.fx = -1;
  EXPECT_FALSE(c.IsValid());
  c = good;
  c.cy = std::nan("");
  EXPECT_FALSE(c.IsValid());
  c = good;
  c.t.x() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(c.IsValid());
  c = good;
  c.R *= 1.01;
  EXPECT_FALSE(c.IsValid());
  c = good;
  c.R = -c.R;  // a reflection
  EXPECT_FALSE(c.IsValid());
}

TEST(CameraTest, LookAtHelperBuildsARightHandedCameraWithYDown) {
  const PinholeCamera c =
      testing::LookAtCamera({0, 0, 0}, {0, 5, 0}, {0, 0, 1}, 100, 80, 50);
  ASSERT_TRUE(c.IsValid());
  // World up (+z) appears towards the top of the image (smaller y).
  EXPECT_LT(c.CameraToPixel(c.WorldToCamera({0, 5, 1})).y(), 40);
  // World +x appears to the right when looking along +y with +z up.
  EXPECT_GT(c.CameraToPixel(c.WorldToCamera({1, 5, 0})).x(), 50);
}

}  // namespace
}  // namespace fvs
