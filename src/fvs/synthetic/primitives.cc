#include "fvs/synthetic/primitives.h"

#include <algorithm>
#include <cmath>

namespace fvs::synthetic {
namespace {

constexpr double kPi = 3.14159265358979323846;

int AddVertex(const Eigen::Vector3d& p, LabeledMesh* out) {
  out->mesh.vertices.push_back(p);
  return static_cast<int>(out->mesh.vertices.size()) - 1;
}

void AddFace(int a, int b, int c, int primitive, int material, LabeledMesh* out) {
  out->mesh.faces.emplace_back(a, b, c);
  out->face_primitive.push_back(primitive);
  out->face_material.push_back(material);
}

int Cells(double length, double max_edge) {
  return std::max(1, static_cast<int>(std::ceil(length / max_edge - 1e-9)));
}

}  // namespace

void AddQuad(const Eigen::Vector3d& origin, const Eigen::Vector3d& edge_u,
             const Eigen::Vector3d& edge_v, double max_edge, int primitive, int material,
             LabeledMesh* out) {
  const int nu = Cells(edge_u.norm(), max_edge);
  const int nv = Cells(edge_v.norm(), max_edge);
  const int first = static_cast<int>(out->mesh.vertices.size());
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      AddVertex(origin + edge_u * (static_cast<double>(i) / nu) +
                    edge_v * (static_cast<double>(j) / nv),
                out);
    }
  }
  auto id = [&](int i, int j) { return first + j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      AddFace(id(i, j), id(i + 1, j), id(i + 1, j + 1), primitive, material, out);
      AddFace(id(i, j), id(i + 1, j + 1), id(i, j + 1), primitive, material, out);
    }
  }
}

void AddBox(const Eigen::Vector3d& center, const Eigen::Vector3d& half,
            const Eigen::Matrix3d& rotation, bool inward, double max_edge, int primitive,
            int material, LabeledMesh* out) {
  // For each axis and sign: the face at centre + sign * half[axis] along that axis, with
  // two edges chosen so that edge_u x edge_v points outwards (or inwards for a room).
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int sign = -1; sign <= 1; sign += 2) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::Zero(),
                      v = Eigen::Vector3d::Zero();
      n[axis] = sign * half[axis];
      u[a1] = 2 * half[a1];
      v[a2] = 2 * half[a2];
      // e_a1 x e_a2 = e_axis: outward for sign +1; swap the edges to flip.
      const bool flip = (sign < 0) != inward;
      if (flip) std::swap(u, v);
      Eigen::Vector3d corner = n;
      corner[a1] = -half[a1];
      corner[a2] = -half[a2];
      AddQuad(center + rotation * corner, rotation * u, rotation * v, max_edge, primitive,
              material, out);
    }
  }
}

void AddSphere(const Eigen::Vector3d& center, double radius, int slices, int stacks,
               int primitive, int material, LabeledMesh* out) {
  const int first = static_cast<int>(out->mesh.vertices.size());
  // Rings from the south pole (j = 0) to the north pole (j = stacks); poles duplicated
  // per slice keeps the indexing simple (degenerate-free: the pole triangles are emitted
  // once).
  for (int j = 0; j <= stacks; ++j) {
    const double theta = -kPi / 2 + kPi * j / stacks;
    for (int i = 0; i <= slices; ++i) {
      const double phi = 2 * kPi * i / slices;
      AddVertex(center + radius * Eigen::Vector3d(std::cos(theta) * std::cos(phi),
                                                  std::cos(theta) * std::sin(phi),
                                                  std::sin(theta)),
                out);
    }
  }
  auto id = [&](int i, int j) { return first + j * (slices + 1) + i; };
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < slices; ++i) {
      // Counter-clockwise seen from outside: phi grows to the east, theta to the north.
      if (j > 0)
        AddFace(id(i, j), id(i + 1, j), id(i + 1, j + 1), primitive, material, out);
      if (j < stacks - 1) {
        AddFace(id(i, j), id(i + 1, j + 1), id(i, j + 1), primitive, material, out);
      }
    }
  }
}

void AddCylinder(const Eigen::Vector3d& base_center, double radius, double height,
                 int slices, double max_edge, int primitive, int material,
                 LabeledMesh* out) {
  const int rows = Cells(height, max_edge);
  const int first = static_cast<int>(out->mesh.vertices.size());
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= slices; ++i) {
      const double phi = 2 * kPi * i / slices;
      AddVertex(base_center + Eigen::Vector3d(radius * std::cos(phi),
                                              radius * std::sin(phi), height * j / rows),
                out);
    }
  }
  auto id = [&](int i, int j) { return first + j * (slices + 1) + i; };
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < slices; ++i) {
      AddFace(id(i, j), id(i + 1, j), id(i + 1, j + 1), primitive, material, out);
      AddFace(id(i, j), id(i + 1, j + 1), id(i, j + 1), primitive, material, out);
    }
  }
  // Caps as fans around their own centre vertex.
  for (int cap = 0; cap < 2; ++cap) {
    const double z = cap ? height : 0.0;
    const int centre = AddVertex(base_center + Eigen::Vector3d(0, 0, z), out);
    const int ring = static_cast<int>(out->mesh.vertices.size());
    for (int i = 0; i <= slices; ++i) {
      const double phi = 2 * kPi * i / slices;
      AddVertex(base_center +
                    Eigen::Vector3d(radius * std::cos(phi), radius * std::sin(phi), z),
                out);
    }
    for (int i = 0; i < slices; ++i) {
      if (cap) {
        AddFace(centre, ring + i, ring + i + 1, primitive, material, out);  // normal +z
      } else {
        AddFace(centre, ring + i + 1, ring + i, primitive, material, out);  // normal -z
      }
    }
  }
}

}  // namespace fvs::synthetic
