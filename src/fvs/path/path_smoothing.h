// The Ceres problem behind CameraPathOptions::smooth (see camera_path.h for the terms).
// Positions are in the spline's scaled frame; rotations are unit quaternions on Ceres'
// EigenQuaternionManifold, with their jerk taken on the (sign-aligned) components, which
// for small steps is half the angular jerk.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fvs/path/path_spline.h"

namespace fvs {

struct PathSmoothingProblem {
  std::vector<PathPose> initial;  // one per frame (also the prior)
  std::vector<PathPose> keys;     // keyframe poses
  std::vector<double> key_frame;  // fractional frame index of each key
  // Coverage pulls: frame j is drawn towards pull_target[j] with pull_weight[j] (0:
  // none).
  std::vector<Eigen::Vector3d> pull_target;
  std::vector<double> pull_weight;
  // Look term: hinge max(0, look_min_cos[j] - cos(angle to look_centre)); off if empty.
  Eigen::Vector3d look_centre = Eigen::Vector3d::Zero();
  std::vector<double> look_min_cos;
};

// Starts from `start` (initial when empty) and returns the optimised poses. Returns the
// start unchanged when there are fewer than 4 frames (no jerk to speak of) or when the
// solver produced anything non-finite.
std::vector<PathPose> SmoothPath(const PathSmoothingProblem& problem,
                                 const std::vector<PathPose>& start,
                                 const CameraPathOptions& options);

// Sum over frames of |third difference|^2 of positions / quaternion components,
// in continuous time over the whole path (times (n-1)^5).
double PositionJerkEnergy(const std::vector<PathPose>& poses);
double RotationJerkEnergy(const std::vector<PathPose>& poses);

}  // namespace fvs
