// A pinhole camera placed by eye, target and up direction, for generated scenes, tests
// and benchmarks. (Kept out of camera.h, which nearly every file includes.)
#pragma once

#include <Eigen/Geometry>

#include "fvs/geometry/camera.h"

namespace fvs {

// At `eye`, looking at `target`, principal point at the image centre, fx = fy = focal.
// Axes: z towards the target, x = z x up (so `up` points up in the image, y being down),
// y = z x x. `up` must not be parallel to the viewing direction.
inline PinholeCamera LookAtCamera(const Eigen::Vector3d& eye,
                                  const Eigen::Vector3d& target, int width, int height,
                                  double focal,
                                  const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ()) {
  PinholeCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = focal;
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(up).normalized();
  const Eigen::Vector3d y = z.cross(x);
  c.R.row(0) = x.transpose();
  c.R.row(1) = y.transpose();
  c.R.row(2) = z.transpose();
  c.t = -c.R * eye;
  return c;
}

}  // namespace fvs
