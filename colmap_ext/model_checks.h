// Validation of sparse-model parts, shared by Reconstruction::Check and the readers
// (which name the file a fault was found in). Private to colmap_ext.
#pragma once

#include <string>

#include "colmap_ext/reconstruction.h"

namespace fvs::colmap::internal {

// Known model, matching parameter count, positive size, finite parameters.
void CheckCamera(const Camera& camera, const std::string& subject);
// Finite, non-zero quaternion; finite translation and 2D points.
void CheckImage(const Image& image, const std::string& subject);
// Finite position and error.
void CheckPoint3D(uint64_t point3D_id, const Point3D& point, const std::string& subject);
// Ids that refer to something missing: images -> cameras and points3D, tracks -> images
// and their 2D points.
void CheckReferences(const Reconstruction& reconstruction,
                     const std::string& images_subject,
                     const std::string& points_subject);

}  // namespace fvs::colmap::internal
