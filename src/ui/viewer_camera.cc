#include "ui/viewer_camera.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace fvs::ui {

ViewerCamera::ViewerCamera() : fov_y_(50.0 * M_PI / 180.0) {}

void ViewerCamera::LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                          const Eigen::Vector3d& up) {
  Eigen::Vector3d z = target - eye;
  const double distance = z.norm();
  if (!(distance > 1e-12) || !std::isfinite(distance)) return;
  z /= distance;
  Eigen::Vector3d x = z.cross(-up);  // camera y points down, so -up
  if (x.norm() < 1e-9) x = z.unitOrthogonal();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  R_.row(0) = x.transpose();
  R_.row(1) = y.transpose();
  R_.row(2) = z.transpose();
  center_ = eye;
  focus_distance_ = distance;
}

void ViewerCamera::LookThrough(const PinholeCamera& camera, double focus_distance) {
  if (!camera.IsValid()) return;
  R_ = camera.R;
  center_ = camera.Center();
  focus_distance_ = std::max(focus_distance, 1e-6);
  set_fov_y(2.0 * std::atan(0.5 * camera.height / camera.fy));
}

Eigen::Vector3d ViewerCamera::focus() const {
  return center_ + focus_distance_ * R_.row(2).transpose();
}

void ViewerCamera::Orbit(double yaw_radians, double pitch_radians,
                         const Eigen::Vector3d& up) {
  const Eigen::Vector3d pivot = focus();
  const Eigen::Vector3d right = R_.row(0).transpose();
  const Eigen::Matrix3d Q = (Eigen::AngleAxisd(-yaw_radians, up.normalized()) *
                             Eigen::AngleAxisd(-pitch_radians, right))
                                .toRotationMatrix();
  center_ = pivot + Q * (center_ - pivot);
  R_ = R_ * Q.transpose();  // camera-to-world turns by Q
  Orthonormalize();
}

void ViewerCamera::Pan(double dx, double dy) {
  const double extent = 2.0 * focus_distance_ * std::tan(0.5 * fov_y_);
  const Eigen::Vector3d offset = R_.transpose() * Eigen::Vector3d(-dx, -dy, 0) * extent;
  center_ += offset;
}

void ViewerCamera::Zoom(double factor) {
  if (!(factor > 0) || !std::isfinite(factor)) return;
  const Eigen::Vector3d pivot = focus();
  focus_distance_ = std::max(focus_distance_ * factor, 1e-6);
  center_ = pivot - focus_distance_ * R_.row(2).transpose();
}

void ViewerCamera::Fly(const Eigen::Vector3d& camera_frame_offset) {
  if (!camera_frame_offset.allFinite()) return;
  center_ += R_.transpose() * camera_frame_offset;
}

void ViewerCamera::set_fov_y(double radians) {
  if (std::isfinite(radians)) fov_y_ = std::clamp(radians, 1e-3, M_PI * 0.95);
}

PinholeCamera ViewerCamera::ToPinhole(int width, int height) const {
  PinholeCamera camera;
  camera.width = std::max(width, 1);
  camera.height = std::max(height, 1);
  camera.fy = 0.5 * camera.height / std::tan(0.5 * fov_y_);
  camera.fx = camera.fy;
  camera.cx = 0.5 * camera.width;
  camera.cy = 0.5 * camera.height;
  camera.R = R_;
  camera.t = -R_ * center_;
  return camera;
}

Eigen::Matrix4d ViewerCamera::ViewMatrix() const {
  // Our camera frame has y down and z forward; OpenGL's eye frame has y up, z backward.
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();
  view.topLeftCorner<3, 3>() = flip * R_;
  view.topRightCorner<3, 1>() = flip * (-R_ * center_);
  return view;
}

Eigen::Matrix4d ViewerCamera::ProjectionMatrix(double aspect, double near_plane,
                                               double far_plane) const {
  const double f = 1.0 / std::tan(0.5 * fov_y_);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / std::max(aspect, 1e-9);
  p(1, 1) = f;
  p(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
  p(2, 3) = 2.0 * far_plane * near_plane / (near_plane - far_plane);
  p(3, 2) = -1.0;
  return p;
}

void ViewerCamera::Orthonormalize() {
  Eigen::Quaterniond q(R_);
  q.normalize();
  R_ = q.toRotationMatrix();
}

}  // namespace fvs::ui
