// The interpolating curve through the keyframes, in a centred and scaled frame
// (x = (centre - origin) / scale), so that far-from-origin paths and tiny or huge scenes
// are all solved with numbers of order one.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "fvs/path/camera_path.h"

namespace fvs {

// One pose of the curve: position (scaled frame), world->camera rotation as a
// quaternion, vertical field of view in radians.
struct PathPose {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  double fov = 1.0;
};

class PathSpline {
 public:
  // Throws fvs::Error for no keyframes or an invalid camera.
  explicit PathSpline(const std::vector<CameraPathKeyframe>& keys);

  int num_keys() const { return static_cast<int>(keys_.size()); }
  const PathPose& key(int i) const { return keys_[i]; }
  const Eigen::Vector3d& origin() const { return origin_; }
  double scale() const { return scale_; }

  // u in [0, num_keys - 1]: key i at u = i. Catmull-Rom in position, squad in rotation,
  // linear in field of view.
  PathPose Evaluate(double u) const;

  Eigen::Vector3d ToScaled(const Eigen::Vector3d& world) const {
    return (world - origin_) / scale_;
  }
  Eigen::Vector3d ToWorld(const Eigen::Vector3d& scaled) const {
    return scaled * scale_ + origin_;
  }

 private:
  std::vector<PathPose> keys_;
  std::vector<Eigen::Quaterniond> squad_controls_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double scale_ = 1.0;
};

// Quaternion log / exp (unit quaternions, pure-vector logs), stable near identity.
Eigen::Vector3d QuaternionLog(const Eigen::Quaterniond& q);
Eigen::Quaterniond QuaternionExp(const Eigen::Vector3d& v);

// The parameters u (one per frame, non-decreasing) of num_frames frames: uniform in u,
// or equally spaced along the arc length sqrt(|dx|^2 + (rotation_arc_scale * dtheta)^2)
// when constant_speed (uniform again when the arc has no length).
std::vector<double> FrameParameters(const PathSpline& spline, int num_frames,
                                    bool constant_speed, double rotation_arc_scale);

}  // namespace fvs
