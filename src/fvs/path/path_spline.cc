#include "fvs/path/path_spline.h"

#include <algorithm>
#include <cmath>

#include "fvs/util/error.h"

namespace fvs {

Eigen::Vector3d QuaternionLog(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return Eigen::Vector3d::Zero();
  // atan2 keeps the angle accurate both near 0 and near pi.
  return std::atan2(s, q.w()) / s * v;
}

Eigen::Quaterniond QuaternionExp(const Eigen::Vector3d& v) {
  const double a = v.norm();
  if (a < 1e-12) return Eigen::Quaterniond(1, v.x(), v.y(), v.z()).normalized();
  const Eigen::Vector3d axis = std::sin(a) / a * v;
  return Eigen::Quaterniond(std::cos(a), axis.x(), axis.y(), axis.z());
}

PathSpline::PathSpline(const std::vector<CameraPathKeyframe>& keys) {
  Require(!keys.empty(), "camera path", "needs at least one keyframe");
  for (size_t i = 0; i < keys.size(); ++i) {
    Require(keys[i].camera.IsValid(), "camera path",
            "keyframe " + std::to_string(i) + " (" + keys[i].name +
                ") is not a valid camera");
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& k : keys) mean += k.camera.Center() / static_cast<double>(keys.size());
  double extent = 0;
  for (const auto& k : keys) extent = std::max(extent, (k.camera.Center() - mean).norm());
  origin_ = mean;
  // Twice the radius of the keyframe centres; 1 when they coincide (a pure rotation).
  scale_ = extent > 1e-9 * std::max(1.0, mean.norm()) ? 2 * extent : 1.0;
  for (size_t i = 0; i < keys.size(); ++i) {
    const PinholeCamera& c = keys[i].camera;
    PathPose p;
    p.x = ToScaled(c.Center());
    p.q = Eigen::Quaterniond(c.R).normalized();
    // Shortest way round between consecutive keys.
    if (i > 0 && keys_.back().q.dot(p.q) < 0) p.q.coeffs() *= -1;
    p.fov = 2 * std::atan(0.5 * c.height / c.fy);
    keys_.push_back(p);
  }
  const int n = num_keys();
  squad_controls_.resize(n);
  for (int i = 0; i < n; ++i) {
    if (i == 0 || i == n - 1) {
      squad_controls_[i] = keys_[i].q;
      continue;
    }
    const Eigen::Quaterniond qi_inv = keys_[i].q.conjugate();
    const Eigen::Vector3d sum =
        QuaternionLog(qi_inv * keys_[i + 1].q) + QuaternionLog(qi_inv * keys_[i - 1].q);
    squad_controls_[i] = (keys_[i].q * QuaternionExp(-0.25 * sum)).normalized();
  }
}

namespace {

Eigen::Vector3d UnitChord(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const Eigen::Vector3d d = to - from;
  const double length = d.norm();
  return length > 1e-12 ? Eigen::Vector3d(d / length) : Eigen::Vector3d::Zero();
}

}  // namespace

PathPose PathSpline::Evaluate(double u) const {
  const int n = num_keys();
  if (n == 1) return keys_[0];
  u = std::clamp(u, 0.0, static_cast<double>(n - 1));
  const int i = std::min(static_cast<int>(std::floor(u)), n - 2);
  const double s = u - i;
  const PathPose& a = keys_[i];
  const PathPose& b = keys_[i + 1];
  // Catmull-Rom-like tangents with chord-length weights: the direction is the mean of
  // the unit chords around the key, the length that of this segment's chord, so that
  // unevenly spaced keys neither overshoot nor loop (uniform Catmull-Rom does).
  const auto tangent = [&](int k, double length) -> Eigen::Vector3d {
    Eigen::Vector3d dir = Eigen::Vector3d::Zero();
    if (k > 0) dir += UnitChord(keys_[k - 1].x, keys_[k].x);
    if (k + 1 < n) dir += UnitChord(keys_[k].x, keys_[k + 1].x);
    if (k > 0 && k + 1 < n) dir *= 0.5;
    return length * dir;
  };
  const double chord = (b.x - a.x).norm();
  const Eigen::Vector3d ma = tangent(i, chord);
  const Eigen::Vector3d mb = tangent(i + 1, chord);
  const double s2 = s * s, s3 = s2 * s;
  PathPose p;
  p.x = (2 * s3 - 3 * s2 + 1) * a.x + (s3 - 2 * s2 + s) * ma + (-2 * s3 + 3 * s2) * b.x +
        (s3 - s2) * mb;
  const Eigen::Quaterniond outer = a.q.slerp(s, b.q);
  const Eigen::Quaterniond inner = squad_controls_[i].slerp(s, squad_controls_[i + 1]);
  p.q = outer.slerp(2 * s * (1 - s), inner).normalized();
  p.fov = (1 - s) * a.fov + s * b.fov;
  return p;
}

std::vector<double> FrameParameters(const PathSpline& spline, int num_frames,
                                    bool constant_speed, double rotation_arc_scale) {
  const double u_max = spline.num_keys() - 1;
  std::vector<double> u(num_frames, 0.0);
  if (num_frames == 1) return u;
  for (int j = 0; j < num_frames; ++j) u[j] = u_max * j / (num_frames - 1);
  if (!constant_speed || u_max <= 0) return u;
  // Arc length table over a fine sampling of u.
  const int samples = 256 * static_cast<int>(u_max) + 1;
  std::vector<double> table_u(samples), table_s(samples, 0.0);
  PathPose previous = spline.Evaluate(0);
  for (int k = 0; k < samples; ++k) {
    table_u[k] = u_max * k / (samples - 1);
    if (k == 0) continue;
    const PathPose p = spline.Evaluate(table_u[k]);
    const double angle = 2 * QuaternionLog(previous.q.conjugate() * p.q).norm();
    const double dx = (p.x - previous.x).norm();
    table_s[k] = table_s[k - 1] + std::hypot(dx, rotation_arc_scale * angle);
    previous = p;
  }
  const double total = table_s.back();
  if (!(total > 1e-12) || !std::isfinite(total)) return u;
  int k = 0;
  for (int j = 0; j < num_frames; ++j) {
    const double target = total * j / (num_frames - 1);
    while (k + 1 < samples - 1 && table_s[k + 1] < target) ++k;
    const double ds = table_s[k + 1] - table_s[k];
    const double f = ds > 0 ? std::clamp((target - table_s[k]) / ds, 0.0, 1.0) : 0.0;
    u[j] = table_u[k] + f * (table_u[k + 1] - table_u[k]);
  }
  u.back() = u_max;
  return u;
}

}  // namespace fvs
