// A small sparse model that uses every COLMAP camera model: one camera per model, two
// images per camera, 3D points on a grid seen by every image, 2D points made with our own
// projection (plus a few 2D points without a 3D point). Shared by the colmap_ext tests.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/reconstruction.h"

namespace fvs::colmap::testing {

// Realistic parameters for a 640x480 camera of each model.
inline std::vector<double> SampleParams(int model_id) {
  switch (model_id) {
    case kSimplePinhole:
      return {500, 320, 240};
    case kPinhole:
      return {510, 505, 321.5, 239.5};
    case kSimpleRadial:
      return {500, 320, 240, 0.05};
    case kRadial:
      return {500, 320, 240, 0.05, -0.01};
    case kOpenCV:
      return {510, 505, 320, 240, 0.05, -0.02, 0.001, -0.0005};
    case kOpenCVFisheye:
      return {300, 302, 320, 240, 0.02, -0.01, 0.003, -0.001};
    case kFullOpenCV:
      return {510,   505,     320,   240,  0.05,   -0.02,
              0.001, -0.0005, 0.003, 0.01, -0.005, 0.001};
    case kFOV:
      return {400, 401, 320, 240, 0.9};
    case kSimpleRadialFisheye:
      return {300, 320, 240, 0.02};
    case kRadialFisheye:
      return {300, 320, 240, 0.02, -0.005};
    case kThinPrismFisheye:
      return {300,   302,     320,   240,    0.02,   -0.01,
              0.001, -0.0005, 0.002, -0.001, 0.0008, -0.0004};
  }
  return {};
}

// COLMAP normalises quaternions when it reads and writes; a quaternion that is its own
// normalisation survives that bit for bit.
inline Eigen::Vector4d FixedPointNormalized(Eigen::Vector4d q) {
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector4d next = q / q.norm();
    if (next == q) break;
    q = next;
  }
  return q;
}

inline Reconstruction MakeSampleModel(int images_per_camera = 2) {
  Reconstruction rec;
  for (int m = 0; m < kNumCameraModels; ++m) {
    Camera camera;
    camera.camera_id = m + 1;
    camera.model_id = m;
    camera.width = 640;
    camera.height = 480;
    camera.params = SampleParams(m);
    rec.cameras[camera.camera_id] = camera;
  }
  // 3D points on a 5x4 grid at depth ~5 in front of all cameras.
  std::vector<Eigen::Vector3d> world;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) {
      world.emplace_back(-1.2 + 0.6 * i + 0.01 * j, -0.9 + 0.6 * j,
                         5.0 + 0.1 * i - 0.05 * j);
    }
  }
  uint32_t image_id = 1;
  for (const auto& [camera_id, camera] : rec.cameras) {
    for (int k = 0; k < images_per_camera; ++k, ++image_id) {
      Image image;
      image.image_id = image_id;
      image.camera_id = camera_id;
      image.name = "img_" + std::to_string(image_id) + ".png";
      const double angle = 0.02 * image_id;
      const Eigen::Quaterniond q(
          Eigen::AngleAxisd(angle, Eigen::Vector3d(0.3, 1, 0.1).normalized()));
      image.qvec = FixedPointNormalized(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
      image.tvec = Eigen::Vector3d(0.1 * k - 0.05 * image_id, 0.02 * image_id, 0.3);
      const Eigen::Matrix3d R = image.Rotation();
      for (size_t p = 0; p < world.size(); ++p) {
        const Eigen::Vector3d xc = R * world[p] + image.tvec;
        Point2D point;
        point.xy = CameraWorldToImage(camera.model_id, camera.params, xc.hnormalized());
        point.point3D_id = p + 1;
        image.points2D.push_back(point);
      }
      // A 2D point without a 3D point (COLMAP writes -1 in text).
      Point2D lone;
      lone.xy = Eigen::Vector2d(10.25 + image_id, 20.125);
      image.points2D.push_back(lone);
      rec.images[image_id] = image;
    }
  }
  for (size_t p = 0; p < world.size(); ++p) {
    Point3D point;
    point.xyz = world[p];
    point.color = {static_cast<uint8_t>(10 * p), 128, static_cast<uint8_t>(255 - p)};
    point.error = 0.1 + 0.01 * p;
    for (const auto& [id, image] : rec.images) {
      point.track.push_back({id, static_cast<uint32_t>(p)});
    }
    rec.points3D[p + 1] = point;
  }
  return rec;
}

// Exact equality, field by field (bit-exact doubles).
inline bool ModelsEqual(const Reconstruction& a, const Reconstruction& b,
                        std::string* why) {
  auto fail = [&](const std::string& w) {
    *why = w;
    return false;
  };
  if (a.cameras.size() != b.cameras.size()) return fail("camera count");
  for (const auto& [id, ca] : a.cameras) {
    const auto it = b.cameras.find(id);
    if (it == b.cameras.end()) return fail("camera " + std::to_string(id) + " missing");
    const Camera& cb = it->second;
    if (ca.model_id != cb.model_id || ca.width != cb.width || ca.height != cb.height ||
        ca.params != cb.params || ca.camera_id != cb.camera_id) {
      return fail("camera " + std::to_string(id) + " differs");
    }
  }
  if (a.images.size() != b.images.size()) return fail("image count");
  for (const auto& [id, ia] : a.images) {
    const auto it = b.images.find(id);
    if (it == b.images.end()) return fail("image " + std::to_string(id) + " missing");
    const Image& ib = it->second;
    if (ia.qvec != ib.qvec || ia.tvec != ib.tvec || ia.camera_id != ib.camera_id ||
        ia.name != ib.name || ia.points2D.size() != ib.points2D.size()) {
      return fail("image " + std::to_string(id) + " differs");
    }
    for (size_t k = 0; k < ia.points2D.size(); ++k) {
      if (ia.points2D[k].xy != ib.points2D[k].xy ||
          ia.points2D[k].point3D_id != ib.points2D[k].point3D_id) {
        return fail("image " + std::to_string(id) + " point2D " + std::to_string(k));
      }
    }
  }
  if (a.points3D.size() != b.points3D.size()) return fail("point3D count");
  for (const auto& [id, pa] : a.points3D) {
    const auto it = b.points3D.find(id);
    if (it == b.points3D.end()) return fail("point3D " + std::to_string(id) + " missing");
    const Point3D& pb = it->second;
    if (pa.xyz != pb.xyz || pa.color != pb.color || pa.error != pb.error ||
        pa.track.size() != pb.track.size()) {
      return fail("point3D " + std::to_string(id) + " differs");
    }
    for (size_t k = 0; k < pa.track.size(); ++k) {
      if (pa.track[k].image_id != pb.track[k].image_id ||
          pa.track[k].point2D_idx != pb.track[k].point2D_idx) {
        return fail("point3D " + std::to_string(id) + " track");
      }
    }
  }
  return true;
}

}  // namespace fvs::colmap::testing
