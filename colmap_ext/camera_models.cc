// COLMAP 3.8's camera models (src/base/camera_models.h), transcribed model by model so
// that our projections agree with COLMAP's to the last bit where the arithmetic is the
// same.
#include "colmap_ext/camera_models.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "fvs/util/error.h"

namespace fvs::colmap {
namespace {

struct ModelInfo {
  const char* name;
  int num_params;
  const char* params_info;
};

constexpr ModelInfo kModels[kNumCameraModels] = {
    {"SIMPLE_PINHOLE", 3, "f, cx, cy"},
    {"PINHOLE", 4, "fx, fy, cx, cy"},
    {"SIMPLE_RADIAL", 4, "f, cx, cy, k"},
    {"RADIAL", 5, "f, cx, cy, k1, k2"},
    {"OPENCV", 8, "fx, fy, cx, cy, k1, k2, p1, p2"},
    {"OPENCV_FISHEYE", 8, "fx, fy, cx, cy, k1, k2, k3, k4"},
    {"FULL_OPENCV", 12, "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6"},
    {"FOV", 5, "fx, fy, cx, cy, omega"},
    {"SIMPLE_RADIAL_FISHEYE", 4, "f, cx, cy, k"},
    {"RADIAL_FISHEYE", 5, "f, cx, cy, k1, k2"},
    {"THIN_PRISM_FISHEYE", 12, "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1"},
};

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Distortion functions: (u, v) normalised, undistorted -> offset (du, dv). `extra` points
// at the parameters after focal length(s) and principal point.
using DistortionFn = void (*)(const double* extra, double u, double v, double* du,
                              double* dv);

void SimpleRadialDistortion(const double* k, double u, double v, double* du, double* dv) {
  const double r2 = u * u + v * v;
  const double radial = k[0] * r2;
  *du = u * radial;
  *dv = v * radial;
}

void RadialDistortion(const double* k, double u, double v, double* du, double* dv) {
  const double r2 = u * u + v * v;
  const double radial = k[0] * r2 + k[1] * r2 * r2;
  *du = u * radial;
  *dv = v * radial;
}

void OpenCVDistortion(const double* e, double u, double v, double* du, double* dv) {
  const double k1 = e[0], k2 = e[1], p1 = e[2], p2 = e[3];
  const double u2 = u * u;
  const double uv = u * v;
  const double v2 = v * v;
  const double r2 = u2 + v2;
  const double radial = k1 * r2 + k2 * r2 * r2;
  *du = u * radial + 2.0 * p1 * uv + p2 * (r2 + 2.0 * u2);
  *dv = v * radial + 2.0 * p2 * uv + p1 * (r2 + 2.0 * v2);
}

void OpenCVFisheyeDistortion(const double* e, double u, double v, double* du,
                             double* dv) {
  const double k1 = e[0], k2 = e[1], k3 = e[2], k4 = e[3];
  const double r = std::sqrt(u * u + v * v);
  if (r > kEps) {
    const double theta = std::atan(r);
    const double theta2 = theta * theta;
    const double theta4 = theta2 * theta2;
    const double theta6 = theta4 * theta2;
    const double theta8 = theta4 * theta4;
    const double thetad =
        theta * (1.0 + k1 * theta2 + k2 * theta4 + k3 * theta6 + k4 * theta8);
    *du = u * thetad / r - u;
    *dv = v * thetad / r - v;
  } else {
    *du = 0;
    *dv = 0;
  }
}

void FullOpenCVDistortion(const double* e, double u, double v, double* du, double* dv) {
  const double k1 = e[0], k2 = e[1], p1 = e[2], p2 = e[3];
  const double k3 = e[4], k4 = e[5], k5 = e[6], k6 = e[7];
  const double u2 = u * u;
  const double uv = u * v;
  const double v2 = v * v;
  const double r2 = u2 + v2;
  const double r4 = r2 * r2;
  const double r6 = r4 * r2;
  const double radial =
      (1.0 + k1 * r2 + k2 * r4 + k3 * r6) / (1.0 + k4 * r2 + k5 * r4 + k6 * r6);
  *du = u * radial + 2.0 * p1 * uv + p2 * (r2 + 2.0 * u2) - u;
  *dv = v * radial + 2.0 * p2 * uv + p1 * (r2 + 2.0 * v2) - v;
}

// FOV (Devernay & Faugeras): COLMAP's "distortion" returns the distorted point itself,
// with Taylor expansions where the closed form divides by ~0.
void FOVDistortion(const double* e, double u, double v, double* du, double* dv) {
  const double omega = e[0];
  const double kEpsilon = 1e-4;  // COLMAP: "chosen arbitrarily"
  const double radius2 = u * u + v * v;
  const double omega2 = omega * omega;
  double factor;
  if (omega2 < kEpsilon) {
    factor = (omega2 * radius2) / 3.0 - omega2 / 12.0 + 1.0;
  } else if (radius2 < kEpsilon) {
    const double tan_half_omega = std::tan(omega / 2.0);
    factor = (-2.0 * tan_half_omega *
              (4.0 * radius2 * tan_half_omega * tan_half_omega - 3.0)) /
             (3.0 * omega);
  } else {
    const double radius = std::sqrt(radius2);
    const double numerator = std::atan(radius * 2.0 * std::tan(omega / 2.0));
    factor = numerator / (radius * omega);
  }
  *du = u * factor;
  *dv = v * factor;
}

void FOVUndistortion(const double* e, double u, double v, double* du, double* dv) {
  const double omega = e[0];
  const double kEpsilon = 1e-4;
  const double radius2 = u * u + v * v;
  const double omega2 = omega * omega;
  double factor;
  if (omega2 < kEpsilon) {
    factor = (omega2 * radius2) / 3.0 - omega2 / 12.0 + 1.0;
  } else if (radius2 < kEpsilon) {
    factor = (omega * (omega * omega * radius2 + 3.0)) / (6.0 * std::tan(omega / 2.0));
  } else {
    const double radius = std::sqrt(radius2);
    const double numerator = std::tan(radius * omega);
    factor = numerator / (radius * 2.0 * std::tan(omega / 2.0));
  }
  *du = u * factor;
  *dv = v * factor;
}

void SimpleRadialFisheyeDistortion(const double* e, double u, double v, double* du,
                                   double* dv) {
  const double k = e[0];
  const double r = std::sqrt(u * u + v * v);
  if (r > kEps) {
    const double theta = std::atan(r);
    const double theta2 = theta * theta;
    const double thetad = theta * (1.0 + k * theta2);
    *du = u * thetad / r - u;
    *dv = v * thetad / r - v;
  } else {
    *du = 0;
    *dv = 0;
  }
}

void RadialFisheyeDistortion(const double* e, double u, double v, double* du,
                             double* dv) {
  const double k1 = e[0], k2 = e[1];
  const double r = std::sqrt(u * u + v * v);
  if (r > kEps) {
    const double theta = std::atan(r);
    const double theta2 = theta * theta;
    const double theta4 = theta2 * theta2;
    const double thetad = theta * (1.0 + k1 * theta2 + k2 * theta4);
    *du = u * thetad / r - u;
    *dv = v * thetad / r - v;
  } else {
    *du = 0;
    *dv = 0;
  }
}

void ThinPrismFisheyeDistortion(const double* e, double u, double v, double* du,
                                double* dv) {
  const double k1 = e[0], k2 = e[1], p1 = e[2], p2 = e[3];
  const double k3 = e[4], k4 = e[5], sx1 = e[6], sy1 = e[7];
  const double u2 = u * u;
  const double uv = u * v;
  const double v2 = v * v;
  const double r2 = u2 + v2;
  const double r4 = r2 * r2;
  const double r6 = r4 * r2;
  const double r8 = r6 * r2;
  const double radial = k1 * r2 + k2 * r4 + k3 * r6 + k4 * r8;
  *du = u * radial + 2.0 * p1 * uv + p2 * (r2 + 2.0 * u2) + sx1 * r2;
  *dv = v * radial + 2.0 * p2 * uv + p1 * (r2 + 2.0 * v2) + sy1 * r2;
}

// COLMAP's BaseCameraModel::IterativeUndistortion: Newton's method with a
// central-difference Jacobian, at most 100 steps, stopping when the squared step is below
// 1e-10.
Eigen::Vector2d IterativeUndistortion(DistortionFn distortion, const double* extra,
                                      const Eigen::Vector2d& x0) {
  const int kNumIterations = 100;
  const double kMaxStepNorm = 1e-10;
  const double kRelStepSize = 1e-6;
  Eigen::Matrix2d J;
  Eigen::Vector2d x = x0;
  Eigen::Vector2d dx, dx_0b, dx_0f, dx_1b, dx_1f;
  for (int i = 0; i < kNumIterations; ++i) {
    const double step0 = std::max(kEps, std::abs(kRelStepSize * x(0)));
    const double step1 = std::max(kEps, std::abs(kRelStepSize * x(1)));
    distortion(extra, x(0), x(1), &dx(0), &dx(1));
    distortion(extra, x(0) - step0, x(1), &dx_0b(0), &dx_0b(1));
    distortion(extra, x(0) + step0, x(1), &dx_0f(0), &dx_0f(1));
    distortion(extra, x(0), x(1) - step1, &dx_1b(0), &dx_1b(1));
    distortion(extra, x(0), x(1) + step1, &dx_1f(0), &dx_1f(1));
    J(0, 0) = 1 + (dx_0f(0) - dx_0b(0)) / (2 * step0);
    J(0, 1) = (dx_1f(0) - dx_1b(0)) / (2 * step1);
    J(1, 0) = (dx_0f(1) - dx_0b(1)) / (2 * step0);
    J(1, 1) = 1 + (dx_1f(1) - dx_1b(1)) / (2 * step1);
    const Eigen::Vector2d step_x = J.inverse() * (x + dx - x0);
    x -= step_x;
    if (step_x.squaredNorm() < kMaxStepNorm) break;
  }
  return x;
}

void CheckParams(int model_id, const std::vector<double>& params) {
  if (!IsKnownCameraModel(model_id)) {
    throw Error("camera model", "unknown camera model id " + std::to_string(model_id));
  }
  if (static_cast<int>(params.size()) != kModels[model_id].num_params) {
    throw Error("camera model", std::string(kModels[model_id].name) + " needs " +
                                    std::to_string(kModels[model_id].num_params) +
                                    " parameters, got " + std::to_string(params.size()));
  }
}

// Models with one focal length f: params = f, cx, cy, extra...
bool HasSingleFocal(int model_id) {
  return model_id == kSimplePinhole || model_id == kSimpleRadial || model_id == kRadial ||
         model_id == kSimpleRadialFisheye || model_id == kRadialFisheye;
}

DistortionFn DistortionOf(int model_id) {
  switch (model_id) {
    case kSimpleRadial:
      return SimpleRadialDistortion;
    case kRadial:
      return RadialDistortion;
    case kOpenCV:
      return OpenCVDistortion;
    case kOpenCVFisheye:
      return OpenCVFisheyeDistortion;
    case kFullOpenCV:
      return FullOpenCVDistortion;
    case kSimpleRadialFisheye:
      return SimpleRadialFisheyeDistortion;
    case kRadialFisheye:
      return RadialFisheyeDistortion;
    case kThinPrismFisheye:
      return ThinPrismFisheyeDistortion;
    default:
      return nullptr;
  }
}

}  // namespace

bool IsKnownCameraModel(int model_id) {
  return model_id >= 0 && model_id < kNumCameraModels;
}

std::string CameraModelName(int model_id) {
  if (!IsKnownCameraModel(model_id)) {
    throw Error("camera model", "unknown camera model id " + std::to_string(model_id));
  }
  return kModels[model_id].name;
}

int CameraModelIdFromName(const std::string& name) {
  for (int i = 0; i < kNumCameraModels; ++i) {
    if (name == kModels[i].name) return i;
  }
  return -1;
}

int CameraModelNumParams(int model_id) {
  return IsKnownCameraModel(model_id) ? kModels[model_id].num_params : -1;
}

std::string CameraModelParamsInfo(int model_id) {
  return IsKnownCameraModel(model_id) ? kModels[model_id].params_info : "";
}

bool CameraModelIsPinhole(int model_id) {
  return model_id == kSimplePinhole || model_id == kPinhole;
}

namespace {

// Focal lengths, principal point and the distortion parameters after them: models with
// one focal length store (f, cx, cy, ...), the others (fx, fy, cx, cy, ...).
struct Intrinsics {
  double f1, f2, c1, c2;
  const double* extra;
};

Intrinsics SplitParams(int model_id, const std::vector<double>& params) {
  CheckParams(model_id, params);
  const bool single = HasSingleFocal(model_id);
  return {params[0], single ? params[0] : params[1], single ? params[1] : params[2],
          single ? params[2] : params[3], params.data() + (single ? 3 : 4)};
}

}  // namespace

Eigen::Vector2d CameraWorldToImage(int model_id, const std::vector<double>& params,
                                   const Eigen::Vector2d& normalized) {
  const Intrinsics in = SplitParams(model_id, params);
  const double f1 = in.f1, f2 = in.f2, c1 = in.c1, c2 = in.c2;
  const double* extra = in.extra;
  double u = normalized.x();
  double v = normalized.y();
  double x, y;
  if (CameraModelIsPinhole(model_id)) {
    x = u;
    y = v;
  } else if (model_id == kFOV) {
    FOVDistortion(extra, u, v, &x, &y);
  } else {
    if (model_id == kThinPrismFisheye) {
      // The thin-prism model applies its polynomial to the equidistant (theta)
      // coordinates.
      const double r = std::sqrt(u * u + v * v);
      if (r > kEps) {
        const double theta = std::atan(r);
        u = theta * u / r;
        v = theta * v / r;
      }
    }
    double du, dv;
    DistortionOf(model_id)(extra, u, v, &du, &dv);
    x = u + du;
    y = v + dv;
  }
  return {f1 * x + c1, f2 * y + c2};
}

Eigen::Vector2d CameraImageToWorld(int model_id, const std::vector<double>& params,
                                   const Eigen::Vector2d& pixel) {
  const Intrinsics in = SplitParams(model_id, params);
  const double f1 = in.f1, f2 = in.f2, c1 = in.c1, c2 = in.c2;
  const double* extra = in.extra;
  const Eigen::Vector2d uv((pixel.x() - c1) / f1, (pixel.y() - c2) / f2);
  if (CameraModelIsPinhole(model_id)) return uv;
  if (model_id == kFOV) {
    Eigen::Vector2d out;
    FOVUndistortion(extra, uv.x(), uv.y(), &out.x(), &out.y());
    return out;
  }
  Eigen::Vector2d out = IterativeUndistortion(DistortionOf(model_id), extra, uv);
  if (model_id == kThinPrismFisheye) {
    const double theta = out.norm();
    const double theta_cos_theta = theta * std::cos(theta);
    if (theta_cos_theta > kEps) out *= std::sin(theta) / theta_cos_theta;
  }
  return out;
}

}  // namespace fvs::colmap
