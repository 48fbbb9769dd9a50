// Reading COLMAP's database.db (sqlite): cameras and images (names, camera ids, prior
// poses), keypoint counts. Read-only; throws fvs::Error naming the file on anything
// unexpected.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>

#include "colmap_ext/reconstruction.h"

namespace fvs::colmap {

struct DatabaseImage {
  uint32_t image_id = 0;
  std::string name;
  uint32_t camera_id = 0;
  int num_keypoints = 0;
  // Pose prior (COLMAP 3.8's prior_qw..prior_tz columns, world -> camera); only when all
  // seven are present and finite (COLMAP leaves them NULL when unknown).
  bool has_prior_pose = false;
  Eigen::Vector4d prior_qvec = Eigen::Vector4d(1, 0, 0, 0);
  Eigen::Vector3d prior_tvec = Eigen::Vector3d::Zero();
};

struct DatabaseContents {
  std::map<uint32_t, Camera> cameras;
  std::map<uint32_t, DatabaseImage> images;
  int num_matched_pairs = 0;   // rows of `matches` with at least one match
  int num_verified_pairs = 0;  // rows of `two_view_geometries` with inliers
};

DatabaseContents ReadDatabase(const std::string& path);

}  // namespace fvs::colmap
