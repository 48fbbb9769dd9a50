// The 3D view's navigation maths: poses stay rotations, orbiting keeps the focus point,
// the OpenGL matrices project exactly as the pinhole camera does, and camera picking.
#include "ui/viewer_camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "geometry/geometry_test_util.h"
#include "ui/workspace_contents.h"

namespace fvs::ui {
namespace {

// Pixel of a world point through the OpenGL matrices (viewport of width x height).
Eigen::Vector2d ProjectGl(const ViewerCamera& camera, const Eigen::Vector3d& x, int width,
                          int height) {
  const Eigen::Vector4d clip =
      camera.ProjectionMatrix(static_cast<double>(width) / height, 0.01, 100.0) *
      camera.ViewMatrix() * x.homogeneous();
  const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
  // NDC y points up, image rows go down.
  return {0.5 * (ndc.x() + 1.0) * width, 0.5 * (1.0 - ndc.y()) * height};
}

TEST(ViewerCamera, GlMatricesProjectAsThePinholeCamera) {
  ViewerCamera camera;
  camera.LookAt({1.0, -2.0, 0.5}, {0.2, 0.3, 0.1}, {0, 0, 1});
  camera.set_fov_y(0.9);
  camera.Orbit(0.3, -0.2, {0, 0, 1});
  const PinholeCamera pinhole = camera.ToPinhole(640, 360);
  ASSERT_TRUE(pinhole.IsValid());
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0.2, 0.3, 0.1), Eigen::Vector3d(0, 0, 0),
        Eigen::Vector3d(0.5, 0.6, -0.2)}) {
    const Eigen::Vector3d xc = pinhole.WorldToCamera(x);
    ASSERT_GT(xc.z(), 0);
    EXPECT_LT((ProjectGl(camera, x, 640, 360) - pinhole.CameraToPixel(xc)).norm(), 1e-6);
  }
}

TEST(ViewerCamera, OrbitKeepsFocusAndZoomApproaches) {
  ViewerCamera camera;
  camera.LookAt({0, -5, 1}, {0, 0, 0}, {0, 0, 1});
  const Eigen::Vector3d focus = camera.focus();
  EXPECT_LT(focus.norm(), 1e-12);
  for (int i = 0; i < 100; ++i) camera.Orbit(0.07, 0.01, {0, 0, 1});
  EXPECT_LT((camera.focus() - focus).norm(), 1e-9);
  EXPECT_NEAR((camera.center() - focus).norm(), std::sqrt(26.0), 1e-9);
  const Eigen::Matrix3d R = camera.rotation();
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_GT(R.determinant(), 0);
  camera.Zoom(0.5);
  EXPECT_NEAR((camera.center() - focus).norm(), 0.5 * std::sqrt(26.0), 1e-9);
  // Flying forward moves along the view direction, focus point with it.
  const Eigen::Vector3d before = camera.center();
  camera.Fly({0, 0, 1});
  EXPECT_LT((camera.center() - before - R.row(2).transpose()).norm(), 1e-12);
  // Degenerate input changes nothing and never makes NaN.
  camera.Zoom(std::nan(""));
  camera.Fly({std::nan(""), 0, 0});
  camera.LookAt({1, 1, 1}, {1, 1, 1}, {0, 0, 1});
  EXPECT_TRUE(camera.ToPinhole(10, 10).IsValid());
}

TEST(ViewerCamera, LookThroughTakesPoseAndFieldOfView) {
  PinholeCamera source = testing::CenteredCamera(200, 100, 150);
  source.R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  source.t = {0.3, -0.2, 2.0};
  ViewerCamera camera;
  camera.LookThrough(source, 2.0);
  const PinholeCamera back = camera.ToPinhole(200, 100);
  EXPECT_LT((back.R - source.R).norm(), 1e-12);
  EXPECT_LT((back.t - source.t).norm(), 1e-12);
  EXPECT_NEAR(back.fy, 150, 1e-9);
}

TEST(PickCamera, NearestProjectedCentreWithinReach) {
  ViewerCamera viewer;
  viewer.LookAt({0, 0, -10}, {0, 0, 0}, {0, -1, 0});
  const PinholeCamera view = viewer.ToPinhole(400, 300);
  std::vector<PinholeCamera> cameras(3);
  cameras[0].t = -Eigen::Vector3d(0, 0, 0);    // centre (0, 0, 0): image centre
  cameras[1].t = -Eigen::Vector3d(1, 0, 0);    // to the right
  cameras[2].t = -Eigen::Vector3d(0, 0, -20);  // behind the viewer
  const Eigen::Vector2d right = view.CameraToPixel(view.WorldToCamera({1, 0, 0}));
  EXPECT_EQ(PickCamera(cameras, view, 200, 150, 10), 0);
  EXPECT_EQ(PickCamera(cameras, view, right.x() + 3, right.y() - 2, 10), 1);
  EXPECT_EQ(PickCamera(cameras, view, 10, 10, 10), -1);
}

}  // namespace
}  // namespace fvs::ui
