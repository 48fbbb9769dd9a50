// Building blocks of the synthetic scene's mesh. Every primitive gets vertices of its own
// (no sharing with neighbours), so each vertex and face belongs to exactly one primitive
// and one material. Faces are counter-clockwise seen from the side a camera can see
// (outside for objects, inside for the room). Large faces are split into a grid of cells
// no longer than `max_edge`, so that vertex colours (the PLY) and rasterisers downstream
// see detail.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fvs/geometry/mesh.h"

namespace fvs::synthetic {

// A mesh whose faces carry the id of the primitive and of the material they belong to.
struct LabeledMesh {
  TriangleMesh mesh;
  std::vector<int> face_primitive;
  std::vector<int> face_material;
};

// Quad origin, origin + edge_u, origin + edge_u + edge_v, origin + edge_v, split into a
// grid; faces counter-clockwise around edge_u x edge_v.
void AddQuad(const Eigen::Vector3d& origin, const Eigen::Vector3d& edge_u,
             const Eigen::Vector3d& edge_v, double max_edge, int primitive, int material,
             LabeledMesh* out);

// Box with half extents `half`, rotated by `rotation` about its centre. inward = true
// gives a room (faces visible from inside).
void AddBox(const Eigen::Vector3d& center, const Eigen::Vector3d& half,
            const Eigen::Matrix3d& rotation, bool inward, double max_edge, int primitive,
            int material, LabeledMesh* out);

// UV sphere.
void AddSphere(const Eigen::Vector3d& center, double radius, int slices, int stacks,
               int primitive, int material, LabeledMesh* out);

// Upright cylinder (axis +z) from base_center, closed by two caps.
void AddCylinder(const Eigen::Vector3d& base_center, double radius, double height,
                 int slices, double max_edge, int primitive, int material,
                 LabeledMesh* out);

}  // namespace fvs::synthetic
