#include "fvs/geometry/quad_grid.h"

#include <cmath>
#include <cstdint>

namespace fvs {

void AddColouredQuadGrid(TriangleMesh* mesh, const Eigen::Vector3d& corner,
                         const Eigen::Vector3d& u, const Eigen::Vector3d& v, int nu,
                         int nv, const Eigen::Vector3d& offset) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const Eigen::Vector3d p = corner + u * (double(i) / nu) + v * (double(j) / nv);
      mesh->vertices.push_back(p + offset);
      auto channel = [&](double a, double b, double c, double phase) {
        const double s = 0.5 + 0.4 * std::sin(a * p.x() + b * p.y() + c * p.z() + phase);
        return static_cast<uint8_t>(std::lround(255 * s));
      };
      mesh->colors.push_back(Vector3ub(channel(2.1, 1.3, 0.7, 0.0),
                                       channel(0.9, 2.7, 1.9, 1.0),
                                       channel(1.7, 0.5, 2.3, 2.0)));
    }
  }
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int a = base + j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
      mesh->faces.emplace_back(a, b, d);
      mesh->faces.emplace_back(a, d, c);
    }
  }
}

}  // namespace fvs
