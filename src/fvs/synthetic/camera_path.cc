#include "fvs/synthetic/camera_path.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "fvs/synthetic/random.h"
#include "fvs/synthetic/synthetic_scene.h"

namespace fvs::synthetic {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

// Smooth wobble in [-1, 1]: a few slow sinusoids of the frame index with random phases,
// what a hand holding a camera adds to an intended path.
class Wobble {
 public:
  explicit Wobble(SceneRandom* random) {
    for (auto& w : waves_) {
      w.frequency = random->Uniform(0.015, 0.08);  // cycles per frame
      w.phase = random->Uniform(0, 2 * kPi);
      w.amplitude = random->Uniform(0.5, 1.0);
    }
  }
  double operator()(double frame) const {
    double sum = 0, norm = 0;
    for (const auto& w : waves_) {
      sum += w.amplitude * std::sin(2 * kPi * w.frequency * frame + w.phase);
      norm += w.amplitude;
    }
    return sum / norm;
  }

 private:
  struct Wave {
    double frequency, phase, amplitude;
  };
  std::array<Wave, 3> waves_;
};

}  // namespace

Eigen::Matrix3d LookAtRotation(const Eigen::Vector3d& center,
                               const Eigen::Vector3d& target, double roll) {
  const Eigen::Vector3d forward = (target - center).normalized();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (std::abs(forward.dot(up)) > 0.999) up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d right = forward.cross(up).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d r;
  r.row(0) = right.transpose();
  r.row(1) = down.transpose();
  r.row(2) = forward.transpose();
  return Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() * r;
}

std::vector<PinholeCamera> MakeHandheldPath(const SyntheticSceneOptions& options,
                                            const PathLayout& layout,
                                            SceneRandom* random) {
  const int n = options.num_views;
  const double step = std::min(options.path_step_degrees, 360.0 / n) * kDegree;
  const double start = random->Uniform(0, 2 * kPi);
  const double direction = random->Uniform() < 0.5 ? -1.0 : 1.0;
  const Wobble radial(random), height(random), aim_x(random), aim_y(random),
      aim_z(random), roll(random);

  std::vector<PinholeCamera> cameras(n);
  for (int i = 0; i < n; ++i) {
    const double angle = start + direction * step * i;
    const double radius_scale = 1.0 + 0.06 * radial(i);
    Eigen::Vector3d center(layout.radius_x * radius_scale * std::cos(angle),
                           layout.radius_y * radius_scale * std::sin(angle),
                           layout.eye_height + 0.1 * height(i));
    // Per-frame shake: small next to the baseline, but no two frames share a smooth
    // curve.
    const double shake_lo[3] = {-0.01, -0.01, -0.01}, shake_hi[3] = {0.01, 0.01, 0.01};
    double shake_xyz[3];
    random->Uniform3(shake_lo, shake_hi, shake_xyz);
    center += Eigen::Vector3d(shake_xyz[0], shake_xyz[1], shake_xyz[2]);
    const Eigen::Vector3d target =
        layout.target + Eigen::Vector3d(0.3 * aim_x(i), 0.3 * aim_y(i), 0.15 * aim_z(i));
    const double roll_angle = 2.5 * kDegree * roll(i) + random->Symmetric(0.3 * kDegree);
    Eigen::Matrix3d rotation = LookAtRotation(center, target, roll_angle);
    const double tilt = random->Symmetric(0.3 * kDegree);
    const double pan = random->Symmetric(0.3 * kDegree);
    const Eigen::Matrix3d shake = (Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()) *
                                   Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitY()))
                                      .toRotationMatrix();
    rotation = shake * rotation;

    PinholeCamera& camera = cameras[i];
    camera.width = options.width;
    camera.height = options.height;
    camera.fx = camera.fy = options.focal_factor * options.width;
    camera.cx = 0.5 * options.width;
    camera.cy = 0.5 * options.height;
    camera.R = rotation;
    camera.t = -rotation * center;
  }
  return cameras;
}

}  // namespace fvs::synthetic
