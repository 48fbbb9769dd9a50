#include "fvs/path/path_smoothing.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "fvs/util/parallel.h"

namespace fvs {

namespace {

// sqrt(weight) * (b3 - 3 b2 + 3 b1 - b0) over N components.
template <int N>
struct JerkCost {
  explicit JerkCost(double s) : scale(s) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, const T* d, T* r) const {
    for (int i = 0; i < N; ++i)
      r[i] = T(scale) * (d[i] - T(3) * c[i] + T(3) * b[i] - a[i]);
    return true;
  }
  double scale;
};

// sqrt(weight) * ((1 - alpha) a + alpha b - target).
template <int N>
struct AnchorCost {
  AnchorCost(const double* t, double a, double s) : alpha(a), scale(s) {
    for (int i = 0; i < N; ++i) target[i] = t[i];
  }
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    for (int i = 0; i < N; ++i) {
      r[i] = T(scale) * ((T(1) - T(alpha)) * a[i] + T(alpha) * b[i] - T(target[i]));
    }
    return true;
  }
  double target[N];
  double alpha, scale;
};

template <int N>
struct PriorCost {
  PriorCost(const double* t, double s) : scale(s) {
    for (int i = 0; i < N; ++i) target[i] = t[i];
  }
  template <typename T>
  bool operator()(const T* a, T* r) const {
    for (int i = 0; i < N; ++i) r[i] = T(scale) * (a[i] - T(target[i]));
    return true;
  }
  double target[N];
  double scale;
};

// Hinge on the cosine between the view axis (third row of R(q)) and the direction to the
// look centre. q in Eigen's (x, y, z, w) order.
struct LookCost {
  LookCost(const Eigen::Vector3d& c, double m, double s)
      : centre(c), min_cos(m), scale(s) {}
  template <typename T>
  bool operator()(const T* x, const T* q, T* r) const {
    const T dir[3] = {T(2) * (q[0] * q[2] - q[3] * q[1]),
                      T(2) * (q[1] * q[2] + q[3] * q[0]),
                      T(1) - T(2) * (q[0] * q[0] + q[1] * q[1])};
    const T to[3] = {T(centre.x()) - x[0], T(centre.y()) - x[1], T(centre.z()) - x[2]};
    const T norm2 = to[0] * to[0] + to[1] * to[1] + to[2] * to[2];
    r[0] = T(0);
    if (!(norm2 > T(1e-12))) return true;
    const T cosine = (dir[0] * to[0] + dir[1] * to[1] + dir[2] * to[2]) / sqrt(norm2);
    const T gap = T(min_cos) - cosine;
    if (gap > T(0)) r[0] = T(scale) * gap;
    return true;
  }
  Eigen::Vector3d centre;
  double min_cos, scale;
};

template <int N>
double JerkEnergy(
    const std::vector<PathPose>& poses,
    const std::function<Eigen::Matrix<double, N, 1>(const PathPose&)>& get) {
  const int n = static_cast<int>(poses.size());
  if (n < 4) return 0;
  double sum = 0;
  for (int j = 0; j + 3 < n; ++j) {
    sum += (get(poses[j + 3]) - 3 * get(poses[j + 2]) + 3 * get(poses[j + 1]) -
            get(poses[j]))
               .squaredNorm();
  }
  return sum * std::pow(n - 1.0, 5);
}

}  // namespace

double PositionJerkEnergy(const std::vector<PathPose>& poses) {
  return JerkEnergy<3>(poses, [](const PathPose& p) { return p.x; });
}
double RotationJerkEnergy(const std::vector<PathPose>& poses) {
  return JerkEnergy<4>(poses,
                       [](const PathPose& p) { return Eigen::Vector4d(p.q.coeffs()); });
}

std::vector<PathPose> SmoothPath(const PathSmoothingProblem& problem,
                                 const std::vector<PathPose>& start,
                                 const CameraPathOptions& options) {
  const std::vector<PathPose>& from = start.empty() ? problem.initial : start;
  const int n = static_cast<int>(from.size());
  if (n < 4) return from;
  std::vector<Eigen::Vector3d> x(n);
  std::vector<Eigen::Vector4d> q(n);  // Eigen order x, y, z, w
  for (int j = 0; j < n; ++j) {
    x[j] = from[j].x;
    Eigen::Quaterniond qj = from[j].q.normalized();
    if (j > 0 && Eigen::Vector4d(qj.coeffs()).dot(q[j - 1]) < 0) qj.coeffs() *= -1;
    q[j] = qj.coeffs();
  }
  auto aligned = [&](const Eigen::Quaterniond& target, int j) {
    Eigen::Vector4d c = target.coeffs();
    if (c.dot(q[j]) < 0) c = -c;
    return c;
  };

  ceres::Problem::Options problem_options;
  ceres::Problem ceres_problem(problem_options);
  for (int j = 0; j < n; ++j) {
    ceres_problem.AddParameterBlock(x[j].data(), 3);
    ceres_problem.AddParameterBlock(q[j].data(), 4, new ceres::EigenQuaternionManifold);
  }
  const double dt = 1.0 / (n - 1);
  // Jerk, in continuous time and relative to the interpolated path's (at least 1, so a
  // straight path does not inflate the weight).
  const double pos_norm = std::max(1.0, PositionJerkEnergy(problem.initial));
  const double rot_norm = std::max(1.0, RotationJerkEnergy(problem.initial));
  const double jerk_time = std::pow(n - 1.0, 2.5);
  const double pos_jerk_scale = std::sqrt(options.jerk_weight / pos_norm) * jerk_time;
  const double rot_jerk_scale = std::sqrt(options.jerk_weight / rot_norm) * jerk_time;
  for (int j = 0; j + 3 < n; ++j) {
    ceres_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<JerkCost<3>, 3, 3, 3, 3, 3>(
            new JerkCost<3>(pos_jerk_scale)),
        nullptr, x[j].data(), x[j + 1].data(), x[j + 2].data(), x[j + 3].data());
    ceres_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<JerkCost<4>, 4, 4, 4, 4, 4>(
            new JerkCost<4>(rot_jerk_scale)),
        nullptr, q[j].data(), q[j + 1].data(), q[j + 2].data(), q[j + 3].data());
  }
  // Keyframes: the pose at the key's fractional frame index.
  const double key_scale = std::sqrt(options.keyframe_weight);
  for (size_t k = 0; k < problem.keys.size(); ++k) {
    const double f = std::clamp(problem.key_frame[k], 0.0, n - 1.0);
    const int i = std::min(static_cast<int>(std::floor(f)), n - 2);
    const double alpha = f - i;
    ceres_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<AnchorCost<3>, 3, 3, 3>(
            new AnchorCost<3>(problem.keys[k].x.data(), alpha, key_scale)),
        nullptr, x[i].data(), x[i + 1].data());
    const Eigen::Vector4d kq = aligned(problem.keys[k].q, alpha < 0.5 ? i : i + 1);
    ceres_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<AnchorCost<4>, 4, 4, 4>(
            new AnchorCost<4>(kq.data(), alpha, key_scale)),
        nullptr, q[i].data(), q[i + 1].data());
  }
  const double prior_scale = std::sqrt(options.prior_weight * dt);
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d px = problem.initial[j].x;
    const Eigen::Vector4d pq = aligned(problem.initial[j].q, j);
    ceres_problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost<3>, 3, 3>(
                                       new PriorCost<3>(px.data(), prior_scale)),
                                   nullptr, x[j].data());
    ceres_problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost<4>, 4, 4>(
                                       new PriorCost<4>(pq.data(), prior_scale)),
                                   nullptr, q[j].data());
    if (j < static_cast<int>(problem.pull_weight.size()) && problem.pull_weight[j] > 0) {
      ceres_problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PriorCost<3>, 3, 3>(new PriorCost<3>(
              problem.pull_target[j].data(), std::sqrt(problem.pull_weight[j]))),
          nullptr, x[j].data());
    }
    if (j < static_cast<int>(problem.look_min_cos.size()) && options.look_weight > 0) {
      ceres_problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<LookCost, 1, 3, 4>(
              new LookCost(problem.look_centre, problem.look_min_cos[j],
                           std::sqrt(options.look_weight * dt))),
          nullptr, x[j].data(), q[j].data());
    }
  }

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(
          solver.sparse_linear_algebra_library_type)) {
    solver.linear_solver_type = ceres::CGNR;
  }
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = DefaultNumThreads();
  solver.function_tolerance = 1e-10;
  solver.gradient_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-10;
  solver.logging_type = ceres::SILENT;
  solver.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &ceres_problem, &summary);

  std::vector<PathPose> result = from;
  for (int j = 0; j < n; ++j) {
    if (!x[j].allFinite() || !q[j].allFinite() || q[j].norm() < 1e-6) {
      std::fprintf(stderr,
                   "WARNING: camera path smoothing diverged; keeping the "
                   "interpolated path\n");
      return from;
    }
    result[j].x = x[j];
    result[j].q = Eigen::Quaterniond(q[j](3), q[j](0), q[j](1), q[j](2)).normalized();
  }
  return result;
}

}  // namespace fvs
