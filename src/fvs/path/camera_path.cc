#include "fvs/path/camera_path.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "fvs/path/path_smoothing.h"
#include "fvs/path/path_spline.h"
#include "fvs/scene/scene.h"
#include "fvs/scene/source_selection.h"
#include "fvs/geometry/warp.h"
#include "fvs/util/error.h"

namespace fvs {

namespace {

bool Finite(double v) { return std::isfinite(v); }

// Output size from the options and the first keyframe.
void OutputSize(const CameraPathOptions& o, const PinholeCamera& first, int* w, int* h) {
  *w = first.width;
  *h = first.height;
  if (o.width > 0 && o.height > 0) {
    *w = o.width;
    *h = o.height;
  } else if (o.width > 0) {
    *w = o.width;
    *h = std::max(
        1, static_cast<int>(std::lround(1.0 * o.width * first.height / first.width)));
  } else if (o.height > 0) {
    *h = o.height;
    *w = std::max(
        1, static_cast<int>(std::lround(1.0 * o.height * first.width / first.height)));
  }
}

PinholeCamera PoseToCamera(const PathSpline& spline, const PathPose& p, int w, int h) {
  PinholeCamera c;
  c.width = w;
  c.height = h;
  const double fov = std::clamp(p.fov, 1e-3, M_PI - 1e-3);
  c.fy = 0.5 * h / std::tan(0.5 * fov);
  c.fx = c.fy;
  c.cx = 0.5 * w;
  c.cy = 0.5 * h;
  c.R = p.q.normalized().toRotationMatrix();
  c.t = -c.R * spline.ToWorld(p.x);
  return c;
}

std::vector<TargetCamera> ToFrames(const PathSpline& spline,
                                   const std::vector<PathPose>& poses, int w, int h) {
  std::vector<TargetCamera> frames;
  for (size_t j = 0; j < poses.size(); ++j) {
    frames.push_back(
        {FrameName(static_cast<int>(j)), PoseToCamera(spline, poses[j], w, h), ""});
  }
  return frames;
}

// Least-squares point nearest to the optical axes of the registered views (world frame),
// or the mesh centroid when the axes are near parallel.
Eigen::Vector3d SceneCentre(const Scene& scene) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const SceneView& v : scene.views()) {
    const Eigen::Vector3d d = v.camera.ViewDirection();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * v.camera.Center();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  if (eig.eigenvalues()(0) > 1e-2 * scene.num_views()) {
    centre = A.ldlt().solve(b);
  } else {
    for (const auto& x : scene.mesh().vertices) centre += x;
    centre /= std::max<size_t>(1, scene.mesh().vertices.size());
  }
  return centre + scene.origin();
}

double Cosine(const PathPose& p, const Eigen::Vector3d& centre) {
  const Eigen::Vector3d to = centre - p.x;
  if (to.norm() < 1e-12) return 1.0;
  const Eigen::Vector3d dir = p.q.normalized().toRotationMatrix().row(2).transpose();
  return dir.dot(to.normalized());
}

std::vector<double> MeasureCoverage(const Scene& scene,
                                    const std::vector<TargetCamera>& frames,
                                    const CameraPathOptions& o) {
  std::vector<double> coverage;
  for (const TargetCamera& f : frames) {
    coverage.push_back(
        TargetCoverage(scene, f.camera, o.coverage_num_sources, o.coverage_width));
  }
  return coverage;
}

void AddCoverageStats(const std::vector<double>& coverage, double threshold,
                      CameraPathStats* stats) {
  if (coverage.empty()) return;
  stats->min_coverage = *std::min_element(coverage.begin(), coverage.end());
  double sum = 0;
  stats->num_low_coverage = 0;
  for (double c : coverage) {
    sum += c;
    stats->num_low_coverage += c < threshold;
  }
  stats->mean_coverage = sum / coverage.size();
}

}  // namespace

void CameraPathOptions::Check() const {
  const std::string s = "camera path options";
  Require(Finite(fps) && fps > 0 && fps <= 1000, s, "fps must be in (0, 1000]");
  Require(Finite(duration_s) && duration_s >= 0 && duration_s <= 24 * 3600, s,
          "duration must be in [0, 1 day]");
  Require(Finite(seconds_per_keyframe) && seconds_per_keyframe > 0 &&
              seconds_per_keyframe <= 3600,
          s, "seconds_per_keyframe must be in (0, 3600]");
  Require(duration_s * fps <= 1e6, s, "more than a million frames");
  Require(width >= 0 && height >= 0 && width <= 65536 && height <= 65536, s,
          "width and height must be in [0, 65536]");
  for (double w :
       {jerk_weight, keyframe_weight, prior_weight, look_weight, coverage_weight}) {
    Require(Finite(w) && w >= 0, s, "weights must be finite and non-negative");
  }
  Require(
      prior_weight > 0 || keyframe_weight > 0, s,
      "prior_weight or keyframe_weight must be positive (the jerk alone has no unique "
      "minimum)");
  Require(
      Finite(look_max_angle_deg) && look_max_angle_deg > 0 && look_max_angle_deg <= 180,
      s, "look_max_angle_deg must be in (0, 180]");
  Require(
      Finite(coverage_threshold) && coverage_threshold >= 0 && coverage_threshold <= 1, s,
      "coverage_threshold must be in [0, 1]");
  Require(coverage_num_sources >= 1, s, "coverage_num_sources must be at least 1");
  Require(coverage_width >= 0, s, "coverage_width must not be negative");
  Require(coverage_rounds >= 1 && coverage_rounds <= 100, s,
          "coverage_rounds in [1, 100]");
  Require(max_iterations >= 1, s, "max_iterations must be at least 1");
  Require(Finite(rotation_arc_scale) && rotation_arc_scale >= 0, s,
          "rotation_arc_scale must be finite and non-negative");
}

double TargetCoverage(const Scene& scene, const PinholeCamera& world_camera, int k,
                      int width) {
  PinholeCamera camera = world_camera;
  if (width > 0 && width < camera.width) {
    const int height = std::max(
        1, static_cast<int>(std::lround(1.0 * width * camera.height / camera.width)));
    camera = camera.Resized(width, height);
  }
  camera = scene.ToSceneCamera(camera);
  if (!camera.IsValid()) return 0;
  const Image depth = scene.RenderDepth(camera);
  SourceSelectionOptions selection;
  selection.k = k;
  const std::vector<SourceScore> sources = SelectSources(scene, camera, depth, selection);
  std::vector<uint8_t> seen(depth.data.size(), 0);
  for (const SourceScore& s : sources) {
    const WarpMap map = ComputeWarpMap(camera, depth, scene.view(s.view_index).camera,
                                       scene.SourceDepth(s.view_index));
    for (size_t i = 0; i < seen.size(); ++i) {
      if (map.valid_warp.data[i] > 0 && map.valid_depth.data[i] > 0) seen[i] = 1;
    }
  }
  size_t count = 0;
  for (uint8_t v : seen) count += v;
  return seen.empty() ? 0.0 : static_cast<double>(count) / seen.size();
}

CameraPathStats MeasureCameraPath(const std::vector<TargetCamera>& frames,
                                  const std::vector<CameraPathKeyframe>& keys,
                                  const std::vector<double>& keyframe_frame) {
  CameraPathStats stats;
  const int n = static_cast<int>(frames.size());
  std::vector<Eigen::Vector4d> q(n);
  for (int j = 0; j < n; ++j) {
    Eigen::Quaterniond qj(frames[j].camera.R);
    q[j] = qj.normalized().coeffs();
    if (j > 0 && q[j].dot(q[j - 1]) < 0) q[j] = -q[j];
  }
  if (n >= 4) {
    double pos = 0, rot = 0;
    for (int j = 0; j + 3 < n; ++j) {
      const auto c = [&](int i) { return frames[i].camera.Center(); };
      pos += (c(j + 3) - 3 * c(j + 2) + 3 * c(j + 1) - c(j)).squaredNorm();
      rot += (q[j + 3] - 3 * q[j + 2] + 3 * q[j + 1] - q[j]).squaredNorm();
    }
    stats.jerk = std::sqrt(pos / (n - 3));
    stats.rotation_jerk = std::sqrt(rot / (n - 3));
  }
  for (size_t k = 0; k < keys.size() && k < keyframe_frame.size() && n > 0; ++k) {
    const double f = std::clamp(keyframe_frame[k], 0.0, n - 1.0);
    const int i = std::min(static_cast<int>(std::floor(f)), std::max(0, n - 2));
    const int i1 = std::min(i + 1, n - 1);
    const double a = f - i;
    const Eigen::Vector3d centre =
        (1 - a) * frames[i].camera.Center() + a * frames[i1].camera.Center();
    stats.keyframe_error =
        std::max(stats.keyframe_error, (centre - keys[k].camera.Center()).norm());
    const Eigen::Quaterniond qa(frames[i].camera.R), qb(frames[i1].camera.R);
    const Eigen::Quaterniond qf = qa.slerp(a, qb);
    const double angle = qf.angularDistance(Eigen::Quaterniond(keys[k].camera.R));
    stats.keyframe_angle_deg = std::max(stats.keyframe_angle_deg, angle * 180 / M_PI);
  }
  return stats;
}

CameraPathResult ComputeCameraPath(const std::vector<CameraPathKeyframe>& keys,
                                   const CameraPathOptions& options, const Scene* scene) {
  options.Check();
  const PathSpline spline(keys);
  const double duration = options.duration_s > 0
                              ? options.duration_s
                              : options.seconds_per_keyframe * (spline.num_keys() - 1);
  const int num_frames =
      std::max(1, static_cast<int>(std::lround(duration * options.fps)) + 1);
  const std::vector<double> u = FrameParameters(
      spline, num_frames, options.constant_speed, options.rotation_arc_scale);
  int w = 0, h = 0;
  OutputSize(options, keys.front().camera, &w, &h);

  CameraPathResult result;
  // Fractional frame index of each key (u is non-decreasing).
  for (int k = 0; k < spline.num_keys(); ++k) {
    double f = 0;
    if (num_frames > 1 && spline.num_keys() > 1) {
      const auto it = std::lower_bound(u.begin(), u.end(), static_cast<double>(k));
      const int j = static_cast<int>(it - u.begin());
      if (j >= num_frames) {
        f = num_frames - 1;
      } else if (j == 0) {
        f = 0;
      } else {
        const double du = u[j] - u[j - 1];
        f = du > 0 ? (j - 1) + (k - u[j - 1]) / du : j;
      }
    }
    result.keyframe_frame.push_back(f);
  }

  PathSmoothingProblem problem;
  for (double uj : u) problem.initial.push_back(spline.Evaluate(uj));
  for (int k = 0; k < spline.num_keys(); ++k) problem.keys.push_back(spline.key(k));
  problem.key_frame = result.keyframe_frame;

  result.frames = ToFrames(spline, problem.initial, w, h);
  result.before = MeasureCameraPath(result.frames, keys, result.keyframe_frame);
  if (scene) {
    result.coverage = MeasureCoverage(*scene, result.frames, options);
    AddCoverageStats(result.coverage, options.coverage_threshold, &result.before);
  }
  if (!options.smooth || num_frames < 4) {
    result.after = result.before;
    return result;
  }

  std::vector<Eigen::Vector3d> sources;  // registered centres, scaled frame
  if (scene) {
    problem.look_centre = spline.ToScaled(SceneCentre(*scene));
    const double strict = std::cos(options.look_max_angle_deg * M_PI / 180);
    // Smoothing may not turn a frame further from the scene than the interpolated path
    // does (beyond the allowed angle); low-coverage frames get the strict bound below.
    for (const PathPose& p : problem.initial) {
      problem.look_min_cos.push_back(
          std::min(strict, Cosine(p, problem.look_centre) - 0.05));
    }
    for (const SceneView& v : scene->views()) {
      sources.push_back(spline.ToScaled(v.camera.Center() + scene->origin()));
    }
    problem.pull_target.assign(num_frames, Eigen::Vector3d::Zero());
    problem.pull_weight.assign(num_frames, 0.0);
  }

  std::vector<PathPose> poses;
  std::vector<double> coverage = result.coverage;
  const int rounds = scene ? options.coverage_rounds : 1;
  for (int round = 0; round < rounds; ++round) {
    if (scene && round > 0) {
      // Penalise the frames still under the threshold: pull them towards the nearest
      // registered camera, more the less they see, and insist on the look direction.
      bool any = false;
      for (int j = 0; j < num_frames; ++j) {
        if (coverage[j] >= options.coverage_threshold) continue;
        any = true;
        double best = std::numeric_limits<double>::infinity();
        for (const Eigen::Vector3d& s : sources) {
          const double d = (s - poses[j].x).squaredNorm();
          if (d < best) {
            best = d;
            problem.pull_target[j] = s;
          }
        }
        const double deficit =
            options.coverage_threshold > 0
                ? (options.coverage_threshold - coverage[j]) / options.coverage_threshold
                : 0.0;
        problem.pull_weight[j] += options.coverage_weight * deficit;
        problem.look_min_cos[j] = std::cos(options.look_max_angle_deg * M_PI / 180);
      }
      if (!any) break;
    }
    poses = SmoothPath(problem, poses, options);
    result.frames = ToFrames(spline, poses, w, h);
    if (scene) coverage = MeasureCoverage(*scene, result.frames, options);
  }
  result.coverage = coverage;
  result.after = MeasureCameraPath(result.frames, keys, result.keyframe_frame);
  AddCoverageStats(result.coverage, options.coverage_threshold, &result.after);
  for (const TargetCamera& f : result.frames) {
    Require(f.camera.IsValid(), "camera path",
            "produced an invalid camera (" + f.name + ")");
  }
  return result;
}

std::vector<TargetCamera> InterpolateCameraPath(
    const std::vector<CameraPathKeyframe>& keys, const CameraPathOptions& options,
    const Scene* scene) {
  return ComputeCameraPath(keys, options, scene).frames;
}

std::vector<CameraPathKeyframe> KeyframesFromScene(
    const Scene& scene, const std::vector<std::string>& names) {
  std::vector<CameraPathKeyframe> keys;
  for (const std::string& name : names) {
    const int index = scene.FindView(name);
    Require(index >= 0, name, "is not a registered image of the workspace");
    keys.push_back({name, scene.ToWorldCamera(scene.view(index).camera)});
  }
  return keys;
}

}  // namespace fvs
