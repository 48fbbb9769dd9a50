#include "fvs/geometry/raster_clip.h"

#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace fvs::raster_internal {

namespace {

// Round to nearest (even) without a libm call: std::lrint is not inlined while errno
// handling is on.
inline int32_t RoundToInt(double x) {
#if defined(__SSE2__)
  return _mm_cvtsd_si32(_mm_set_sd(x));
#else
  return static_cast<int32_t>(std::lrint(x));
#endif
}

}  // namespace

bool SnapToFixed(const PinholeCamera& camera, const Eigen::Vector3d& p, int32_t* x,
                 int32_t* y) {
  const double inv_z = 1.0 / p.z();
  const double u = camera.fx * (p.x() * inv_z) + camera.cx;
  const double v = camera.fy * (p.y() * inv_z) + camera.cy;
  // Written so that NaN fails too.
  if (!(u > -kGuardPixels && u < camera.width + kGuardPixels && v > -kGuardPixels &&
        v < camera.height + kGuardPixels)) {
    return false;
  }
  *x = RoundToInt((u - 0.5) * kSubPixel);
  *y = RoundToInt((v - 0.5) * kSubPixel);
  return true;
}

ClipPlanes MakeClipPlanes(const PinholeCamera& c, double near_plane) {
  const double g = 0.5 * kGuardPixels;
  ClipPlanes p;
  p.planes[0] = {0, 0, 1, -near_plane};
  p.planes[1] = {c.fx, 0, c.cx + g, 0};              // u >= -g
  p.planes[2] = {-c.fx, 0, c.width + g - c.cx, 0};   // u <= width + g
  p.planes[3] = {0, c.fy, c.cy + g, 0};              // v >= -g
  p.planes[4] = {0, -c.fy, c.height + g - c.cy, 0};  // v <= height + g
  return p;
}

namespace {

bool LexLess(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  if (a.x() != b.x()) return a.x() < b.x();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.z() < b.z();
}

Eigen::Vector3d Cut(const Eigen::Vector3d& a, double da, const Eigen::Vector3d& b,
                    double db) {
  if (LexLess(b, a)) return Cut(b, db, a, da);
  const double s = da / (da - db);
  return a + s * (b - a);
}

}  // namespace

void ClipPolygon(const ClipPlanes& planes, Polygon* polygon) {
  for (const Eigen::Vector4d& plane : planes.planes) {
    if (polygon->size < 3) {
      polygon->size = 0;
      return;
    }
    double dist[Polygon::kMaxVertices];
    bool all_inside = true;
    for (int i = 0; i < polygon->size; ++i) {
      dist[i] = plane.head<3>().dot(polygon->v[i]) + plane[3];
      all_inside = all_inside && dist[i] >= 0;
    }
    if (all_inside) continue;
    Polygon out;
    for (int i = 0; i < polygon->size; ++i) {
      const int j = (i + 1) % polygon->size;
      const bool in_i = dist[i] >= 0, in_j = dist[j] >= 0;
      if (in_i && out.size < Polygon::kMaxVertices) out.v[out.size++] = polygon->v[i];
      if (in_i != in_j && out.size < Polygon::kMaxVertices) {
        out.v[out.size++] = Cut(polygon->v[i], dist[i], polygon->v[j], dist[j]);
      }
    }
    *polygon = out;
  }
  if (polygon->size < 3) polygon->size = 0;
}

}  // namespace fvs::raster_internal
