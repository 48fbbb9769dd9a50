// COLMAP's camera models (ids, names, parameter layouts and distortion as in COLMAP 3.8's
// src/base/camera_models.h): projection of normalised camera coordinates to pixels and
// back.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace fvs::colmap {

enum CameraModelId : int {
  kSimplePinhole = 0,        // f, cx, cy
  kPinhole = 1,              // fx, fy, cx, cy
  kSimpleRadial = 2,         // f, cx, cy, k
  kRadial = 3,               // f, cx, cy, k1, k2
  kOpenCV = 4,               // fx, fy, cx, cy, k1, k2, p1, p2
  kOpenCVFisheye = 5,        // fx, fy, cx, cy, k1, k2, k3, k4
  kFullOpenCV = 6,           // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6
  kFOV = 7,                  // fx, fy, cx, cy, omega
  kSimpleRadialFisheye = 8,  // f, cx, cy, k
  kRadialFisheye = 9,        // f, cx, cy, k1, k2
  kThinPrismFisheye = 10,    // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1
};
constexpr int kNumCameraModels = 11;

bool IsKnownCameraModel(int model_id);
// "SIMPLE_PINHOLE", ...; throws fvs::Error for an unknown id.
std::string CameraModelName(int model_id);
// -1 for an unknown name.
int CameraModelIdFromName(const std::string& name);
// Number of parameters; -1 for an unknown id.
int CameraModelNumParams(int model_id);
// "f, cx, cy, k" style description (COLMAP's params_info).
std::string CameraModelParamsInfo(int model_id);
bool CameraModelIsPinhole(int model_id);  // SIMPLE_PINHOLE or PINHOLE: no distortion

// Normalised camera coordinates (x/z, y/z) -> pixel (COLMAP's WorldToImage).
Eigen::Vector2d CameraWorldToImage(int model_id, const std::vector<double>& params,
                                   const Eigen::Vector2d& normalized);
// Pixel -> normalised camera coordinates (COLMAP's ImageToWorld; iterative undistortion
// for the distorted models, as COLMAP).
Eigen::Vector2d CameraImageToWorld(int model_id, const std::vector<double>& params,
                                   const Eigen::Vector2d& pixel);

}  // namespace fvs::colmap
