// COLMAP's sparse model in memory: cameras, images (poses + 2D points) and 3D points,
// with the ids and conventions of COLMAP 3.8 (qvec = (w, x, y, z), world-to-camera pose).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "fvs/geometry/camera.h"

namespace fvs::colmap {

constexpr uint64_t kInvalidPoint3DId = std::numeric_limits<uint64_t>::max();

struct Camera {
  uint32_t camera_id = 0;
  int model_id = -1;  // see camera_models.h
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;
};

struct Point2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  uint64_t point3D_id = kInvalidPoint3DId;
};

struct Image {
  uint32_t image_id = 0;
  Eigen::Vector4d qvec = Eigen::Vector4d(1, 0, 0, 0);  // world -> camera, (w, x, y, z)
  Eigen::Vector3d tvec = Eigen::Vector3d::Zero();
  uint32_t camera_id = 0;
  std::string name;
  std::vector<Point2D> points2D;

  Eigen::Matrix3d Rotation() const { return QuaternionToRotation(qvec); }
  Eigen::Vector3d ProjectionCenter() const { return -Rotation().transpose() * tvec; }
};

struct TrackElement {
  uint32_t image_id = 0;
  uint32_t point2D_idx = 0;
};

struct Point3D {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<uint8_t, 3> color = {0, 0, 0};
  double error = -1.0;
  std::vector<TrackElement> track;
};

struct Reconstruction {
  std::map<uint32_t, Camera> cameras;
  std::map<uint32_t, Image> images;
  std::map<uint64_t, Point3D> points3D;

  // Throws fvs::Error(subject, ...) on what would break later stages: unknown camera
  // model, wrong parameter count, zero image size, non-finite parameters or poses, a zero
  // quaternion, images referring to missing cameras.
  void Check(const std::string& subject) const;

  const Image* FindImageByName(const std::string& name) const;

  // The pinhole camera of an image whose camera model is SIMPLE_PINHOLE or PINHOLE (what
  // an undistorted dense workspace holds). Throws fvs::Error for distorted models.
  PinholeCamera PinholeFor(uint32_t image_id) const;
};

}  // namespace fvs::colmap
