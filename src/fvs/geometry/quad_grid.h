// Building blocks of the small generated worlds of the tests and of the stability suite
// (view_synthesis_stability): tessellated quads whose vertex colours vary smoothly with
// the position, a Lambertian "texture" that warping and blending can be checked against.
#pragma once

#include <Eigen/Core>

#include "fvs/geometry/mesh.h"

namespace fvs {

// Appends a grid of (nu x nv) quads (two triangles each) spanning corner + [0,1] u +
// [0,1] v. Colours are a function of the position before `offset` is added, so a world
// moved far from the origin keeps its texture exactly.
void AddColouredQuadGrid(TriangleMesh* mesh, const Eigen::Vector3d& corner,
                         const Eigen::Vector3d& u, const Eigen::Vector3d& v, int nu,
                         int nv, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

}  // namespace fvs
