// The 3D view's camera and its navigation, in the style of COLMAP's viewer: orbit around
// a focus point, pan, zoom towards the focus, and fly (WASD). Poses follow
// fvs::PinholeCamera (world-to-camera R, x right, y down, z forward) in the scene frame,
// in double precision; OpenGL matrices are derived from it only for drawing.
#pragma once

#include <Eigen/Core>

#include "fvs/geometry/camera.h"

namespace fvs::ui {

class ViewerCamera {
 public:
  ViewerCamera();

  // Looks from `eye` at `target`; `up` need not be orthogonal to the view direction.
  void LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
              const Eigen::Vector3d& up);
  // Takes the pose and vertical field of view of a camera; the focus point is
  // focus_distance in front of it.
  void LookThrough(const PinholeCamera& camera, double focus_distance);

  // Turns around the focus point: yaw about `up`, pitch about the camera's x axis.
  void Orbit(double yaw_radians, double pitch_radians, const Eigen::Vector3d& up);
  // Moves the camera and its focus point in the image plane by a fraction of the view
  // height at the focus distance (dx right, dy down).
  void Pan(double dx, double dy);
  // Moves towards the focus point: factor < 1 comes closer (keeps a minimum distance).
  void Zoom(double factor);
  // Moves camera and focus point by a camera-frame offset (x right, y down, z forward).
  void Fly(const Eigen::Vector3d& camera_frame_offset);

  const Eigen::Matrix3d& rotation() const { return R_; }  // world -> camera
  const Eigen::Vector3d& center() const { return center_; }
  Eigen::Vector3d focus() const;
  double focus_distance() const { return focus_distance_; }
  double fov_y() const { return fov_y_; }  // radians
  void set_fov_y(double radians);

  // A pinhole camera of this pose, square pixels, principal point at the image centre.
  PinholeCamera ToPinhole(int width, int height) const;
  // OpenGL matrices (column-major once cast to float): world -> eye (OpenGL axes) and
  // eye -> clip for the given aspect ratio and depth range.
  Eigen::Matrix4d ViewMatrix() const;
  Eigen::Matrix4d ProjectionMatrix(double aspect, double near_plane,
                                   double far_plane) const;

 private:
  void Orthonormalize();

  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  double focus_distance_ = 1.0;
  double fov_y_;
};

}  // namespace fvs::ui
