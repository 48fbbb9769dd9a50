#include "colmap_ext/reconstruction.h"

#include <cmath>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/model_checks.h"
#include "fvs/util/error.h"

namespace fvs::colmap {
namespace internal {

void CheckCamera(const Camera& camera, const std::string& subject) {
  const std::string who = "camera " + std::to_string(camera.camera_id);
  if (!IsKnownCameraModel(camera.model_id)) {
    throw Error(subject,
                who + ": unknown camera model id " + std::to_string(camera.model_id));
  }
  const int expected = CameraModelNumParams(camera.model_id);
  if (static_cast<int>(camera.params.size()) != expected) {
    throw Error(subject, who + ": " + CameraModelName(camera.model_id) + " needs " +
                             std::to_string(expected) + " parameters, got " +
                             std::to_string(camera.params.size()));
  }
  if (camera.width == 0 || camera.height == 0) {
    throw Error(subject, who + ": zero image size " + std::to_string(camera.width) + "x" +
                             std::to_string(camera.height));
  }
  for (const double p : camera.params) {
    if (!std::isfinite(p)) throw Error(subject, who + ": non-finite camera parameter");
  }
}

void CheckImage(const Image& image, const std::string& subject) {
  const std::string who =
      "image " + std::to_string(image.image_id) + " (" + image.name + ")";
  if (!image.qvec.allFinite() || !image.tvec.allFinite()) {
    throw Error(subject, who + ": non-finite pose (NaN or Inf in qvec/tvec)");
  }
  if (image.qvec.squaredNorm() == 0) throw Error(subject, who + ": zero quaternion");
  if (image.name.empty()) throw Error(subject, who + ": empty image name");
  for (const Point2D& p : image.points2D) {
    if (!p.xy.allFinite()) throw Error(subject, who + ": non-finite 2D point");
  }
}

void CheckPoint3D(uint64_t point3D_id, const Point3D& point, const std::string& subject) {
  if (!point.xyz.allFinite() || !std::isfinite(point.error)) {
    throw Error(subject, "point3D " + std::to_string(point3D_id) +
                             ": non-finite position or error");
  }
}

void CheckReferences(const Reconstruction& rec, const std::string& images_subject,
                     const std::string& points_subject) {
  for (const auto& [image_id, image] : rec.images) {
    if (rec.cameras.count(image.camera_id) == 0) {
      throw Error(images_subject, "image " + std::to_string(image_id) +
                                      " refers to missing camera " +
                                      std::to_string(image.camera_id));
    }
    for (const Point2D& p : image.points2D) {
      if (p.point3D_id != kInvalidPoint3DId && rec.points3D.count(p.point3D_id) == 0) {
        throw Error(images_subject, "image " + std::to_string(image_id) +
                                        " refers to missing point3D " +
                                        std::to_string(p.point3D_id));
      }
    }
  }
  for (const auto& [point_id, point] : rec.points3D) {
    for (const TrackElement& el : point.track) {
      const auto it = rec.images.find(el.image_id);
      if (it == rec.images.end()) {
        throw Error(points_subject, "point3D " + std::to_string(point_id) +
                                        " refers to missing image " +
                                        std::to_string(el.image_id));
      }
      if (el.point2D_idx >= it->second.points2D.size()) {
        throw Error(points_subject, "point3D " + std::to_string(point_id) +
                                        " refers to 2D point " +
                                        std::to_string(el.point2D_idx) + " of image " +
                                        std::to_string(el.image_id) + " which has only " +
                                        std::to_string(it->second.points2D.size()));
      }
    }
  }
}

}  // namespace internal

void Reconstruction::Check(const std::string& subject) const {
  for (const auto& [id, camera] : cameras) {
    if (camera.camera_id != id) {
      throw Error(subject, "camera stored under id " + std::to_string(id) + " has id " +
                               std::to_string(camera.camera_id));
    }
    internal::CheckCamera(camera, subject);
  }
  for (const auto& [id, image] : images) {
    if (image.image_id != id) {
      throw Error(subject, "image stored under id " + std::to_string(id) + " has id " +
                               std::to_string(image.image_id));
    }
    internal::CheckImage(image, subject);
  }
  for (const auto& [id, point] : points3D) internal::CheckPoint3D(id, point, subject);
  internal::CheckReferences(*this, subject, subject);
}

const Image* Reconstruction::FindImageByName(const std::string& name) const {
  for (const auto& [id, image] : images) {
    if (image.name == name) return &image;
  }
  return nullptr;
}

PinholeCamera Reconstruction::PinholeFor(uint32_t image_id) const {
  const auto image_it = images.find(image_id);
  if (image_it == images.end()) {
    throw Error("sparse model", "no image with id " + std::to_string(image_id));
  }
  const Image& image = image_it->second;
  const auto camera_it = cameras.find(image.camera_id);
  if (camera_it == cameras.end()) {
    throw Error("sparse model", "image " + image.name + " refers to missing camera " +
                                    std::to_string(image.camera_id));
  }
  const Camera& camera = camera_it->second;
  internal::CheckCamera(camera, "sparse model");
  internal::CheckImage(image, "sparse model");
  PinholeCamera pinhole;
  if (camera.model_id == kSimplePinhole) {
    pinhole.fx = pinhole.fy = camera.params[0];
    pinhole.cx = camera.params[1];
    pinhole.cy = camera.params[2];
  } else if (camera.model_id == kPinhole) {
    pinhole.fx = camera.params[0];
    pinhole.fy = camera.params[1];
    pinhole.cx = camera.params[2];
    pinhole.cy = camera.params[3];
  } else {
    throw Error("sparse model", "image " + image.name +
                                    " uses the distorted camera model " +
                                    CameraModelName(camera.model_id) +
                                    "; undistort it first (colmap image_undistorter)");
  }
  if (camera.width > static_cast<uint64_t>(1 << 30) ||
      camera.height > static_cast<uint64_t>(1 << 30)) {
    throw Error("sparse model",
                "camera " + std::to_string(camera.camera_id) + ": image size too large");
  }
  pinhole.width = static_cast<int>(camera.width);
  pinhole.height = static_cast<int>(camera.height);
  pinhole.R = image.Rotation();
  pinhole.t = image.tvec;
  return pinhole;
}

}  // namespace fvs::colmap
