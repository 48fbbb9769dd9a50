// The handheld-like camera path of the synthetic scene (see synthetic_scene.h).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fvs/geometry/camera.h"

namespace fvs {
struct SyntheticSceneOptions;
}

namespace fvs::synthetic {

class SceneRandom;

struct PathLayout {
  double radius_x = 3.0;  // semi-axes of the ellipse the path follows (room centre at 0)
  double radius_y = 2.4;
  double eye_height = 1.5;
  Eigen::Vector3d target =
      Eigen::Vector3d(0, 0, 0.6);  // what the camera aims at, on average
};

// Rotation (world -> camera, COLMAP axes: x right, y down, z forward) of a camera at
// `center` looking at `target` with world +z up, rolled by `roll` radians about its axis.
Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& center,
                               const Eigen::Vector3d& target, double roll);

std::vector<PinholeCamera> MakeHandheldPath(const SyntheticSceneOptions& options,
                                            const PathLayout& layout,
                                            SceneRandom* random);

}  // namespace fvs::synthetic
