// A sparse model of exact pinhole cameras, as tests write them: one PINHOLE camera per
// image, ids from 1 in the order added.
#pragma once

#include <cstdint>
#include <string>

#include "colmap_ext/reconstruction.h"
#include "fvs/geometry/camera.h"

namespace fvs::testing {

// Adds camera and image number (size + 1) of `c`, named `name`; returns the image id.
inline uint32_t AddPinholeImage(const PinholeCamera& c, const std::string& name,
                                colmap::Reconstruction* rec) {
  const auto id = static_cast<uint32_t>(rec->images.size() + 1);
  colmap::Camera camera;
  camera.camera_id = id;
  camera.model_id = 1;  // PINHOLE
  camera.width = c.width;
  camera.height = c.height;
  camera.params = {c.fx, c.fy, c.cx, c.cy};
  rec->cameras[id] = camera;
  colmap::Image image;
  image.image_id = id;
  image.camera_id = id;
  image.name = name;
  image.qvec = RotationToQuaternion(c.R);
  image.tvec = c.t;
  rec->images[id] = image;
  return id;
}

}  // namespace fvs::testing
