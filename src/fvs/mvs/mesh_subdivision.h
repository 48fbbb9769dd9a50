// Subdivision of a mesh's long edges, so the mesh refinement has vertices where the
// photos have detail: a mesh meshed from stereo at 400 px and refined at 800 px would
// otherwise only move vertices a few pixels apart, and cannot bend between them.
#pragma once

#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"

namespace fvs::mvs {

// The length of an edge in pixels: the longest of its projections into the cameras in
// front of which both its ends lie and which see its midpoint inside the photo.
// Occlusion is not tested: an edge hidden from a near camera may be split needlessly.
double ProjectedEdgePixels(const std::vector<PinholeCamera>& cameras,
                           const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// Splits every edge longer than max_pixels (ProjectedEdgePixels) at its midpoint, once:
// a face with one, two or three split edges becomes two, three or four faces of the same
// orientation, so the mesh stays conforming and at most quadruples. New vertices get the
// mean colour of the edge's ends; normals are cleared. Returns the number of edges split
// (0: `mesh` is unchanged).
int SubdivideLongEdges(const std::vector<PinholeCamera>& cameras, double max_pixels,
                       TriangleMesh* mesh);

}  // namespace fvs::mvs
