// A pinhole camera in double precision, posed as COLMAP does: x_cam = R * x_world + t
// (world to camera), +z forward, +x right, +y down. Pixel coordinates follow COLMAP: the
// upper-left image corner is (0, 0), the centre of the upper-left pixel is (0.5, 0.5).
// Depth means the camera-frame z of a point (what COLMAP's depth maps hold).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <Eigen/Geometry>
#include <string>

namespace fvs {

struct PinholeCamera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world -> camera rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // world -> camera translation

  Eigen::Matrix3d K() const {
    Eigen::Matrix3d k;
    k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
    return k;
  }
  // Camera centre in world coordinates.
  Eigen::Vector3d Center() const { return -R.transpose() * t; }
  // Viewing direction (+z axis) in world coordinates.
  Eigen::Vector3d ViewDirection() const { return R.row(2).transpose(); }

  Eigen::Vector3d WorldToCamera(const Eigen::Vector3d& x) const { return R * x + t; }
  Eigen::Vector3d CameraToWorld(const Eigen::Vector3d& x) const {
    return R.transpose() * (x - t);
  }
  // Pixel of a camera-frame point (caller checks z > 0).
  Eigen::Vector2d CameraToPixel(const Eigen::Vector3d& xc) const {
    return {fx * xc.x() / xc.z() + cx, fy * xc.y() / xc.z() + cy};
  }
  // Camera-frame point at depth z seen through pixel (u, v).
  Eigen::Vector3d PixelToCamera(double u, double v, double depth) const {
    return {(u - cx) / fx * depth, (v - cy) / fy * depth, depth};
  }
  Eigen::Vector3d Unproject(double u, double v, double depth) const {
    return CameraToWorld(PixelToCamera(u, v, depth));
  }

  // The same camera for an image resized to (new_width, new_height).
  PinholeCamera Resized(int new_width, int new_height) const {
    PinholeCamera c = *this;
    const double sx = static_cast<double>(new_width) / width;
    const double sy = static_cast<double>(new_height) / height;
    c.width = new_width;
    c.height = new_height;
    c.fx *= sx;
    c.cx *= sx;
    c.fy *= sy;
    c.cy *= sy;
    return c;
  }

  // True when every number is finite, sizes and focal lengths are positive and R is a
  // rotation (to 1e-6).
  bool IsValid() const {
    if (width <= 0 || height <= 0) return false;
    if (!(fx > 0 && fy > 0) || !std::isfinite(fx) || !std::isfinite(fy) ||
        !std::isfinite(cx) || !std::isfinite(cy)) {
      return false;
    }
    if (!R.allFinite() || !t.allFinite()) return false;
    return (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
           R.determinant() > 0;
  }
};

// COLMAP's quaternion order is (w, x, y, z).
inline Eigen::Matrix3d QuaternionToRotation(const Eigen::Vector4d& qvec) {
  return Eigen::Quaterniond(qvec(0), qvec(1), qvec(2), qvec(3))
      .normalized()
      .toRotationMatrix();
}
inline Eigen::Vector4d RotationToQuaternion(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;  // canonical sign, as COLMAP
  return {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace fvs
