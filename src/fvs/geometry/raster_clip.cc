#include "fvs/geometry/raster_clip.h"

#include <algorithm>
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

namespace {

using Double4 = double __attribute__((vector_size(32)));
using Int4 = int64_t __attribute__((vector_size(32)));

// Four points; the arithmetic is ToCameraFrame's and SnapToFixed's, lane by lane.
// Inlined into each clone of TransformToScreen, so it is compiled for that clone's ISA.
__attribute__((always_inline)) inline void TransformFour(const PinholeCamera& camera, double near_plane,
                          const Eigen::Vector3d* p, ScreenVertex* out) {
  Double4 px, py, pz;
  for (int k = 0; k < 4; ++k) {
    px[k] = p[k].x();
    py[k] = p[k].y();
    pz[k] = p[k].z();
  }
  const Eigen::Matrix3d& r = camera.R;
  const Double4 x = r(0, 0) * px + r(0, 1) * py + r(0, 2) * pz + camera.t.x();
  const Double4 y = r(1, 0) * px + r(1, 1) * py + r(1, 2) * pz + camera.t.y();
  const Double4 z = r(2, 0) * px + r(2, 1) * py + r(2, 2) * pz + camera.t.z();
  const double fx = camera.fx, fy = camera.fy, cx = camera.cx, cy = camera.cy;
  const double w = camera.width, h = camera.height;
  const Int4 finite = (x - x == 0) & (y - y == 0) & (z - z == 0);
  const Int4 behind = z < near_plane;
  const Double4 inv_z = 1.0 / z;
  const Double4 u = fx * (x * inv_z) + cx;
  const Double4 v = fy * (y * inv_z) + cy;
  const Int4 in_guard = (u > -kGuardPixels) & (u < w + kGuardPixels) &
                        (v > -kGuardPixels) & (v < h + kGuardPixels);
  const Int4 snapped = finite & ~behind & in_guard;
  const Int4 code = ((fx * x + cx * z < 0) & int64_t{kLeft}) |
                    ((fx * x + (cx - w) * z > 0) & int64_t{kRight}) |
                    ((fy * y + cy * z < 0) & int64_t{kTop}) |
                    ((fy * y + (cy - h) * z > 0) & int64_t{kBottom}) |
                    (behind & int64_t{kBehind | kNeedsClip}) |
                    (~behind & ~in_guard & int64_t{kNeedsClip});
  // Round to the nearest integer, ties to even, as cvtsd2si does in RoundToInt: adding
  // and subtracting 1.5 * 2^52 leaves no fraction bits (|value| < 2^51 here).
  constexpr double kMagic = 6755399441055744.0;
  const Double4 zero = {0, 0, 0, 0};
  const Double4 sx = snapped ? ((u - 0.5) * kSubPixel + kMagic) - kMagic : zero;
  const Double4 sy = snapped ? ((v - 0.5) * kSubPixel + kMagic) - kMagic : zero;
  for (int k = 0; k < 4; ++k) {
    out[k].x = static_cast<int32_t>(sx[k]);
    out[k].y = static_cast<int32_t>(sy[k]);
    out[k].code = finite[k] ? static_cast<uint32_t>(code[k]) : kInvalid;
  }
}

}  // namespace

// An AVX2 clone chosen at load time where the CPU has it (faster than SSE2:
// benchmark/README_rasterizer.md), the same roundings either way: no FMA (geometry is built with -ffp-contract=off).
#if defined(__x86_64__) && defined(__GNUC__) && defined(__ELF__)
__attribute__((target_clones("avx2", "default")))
#endif
void TransformToScreen(const PinholeCamera& camera, double near_plane,
                       const Eigen::Vector3d* points, int64_t begin, int64_t end,
                       ScreenVertex* out) {
  int64_t i = begin;
  for (; i + 4 <= end; i += 4) TransformFour(camera, near_plane, points + i, out + i);
  if (i == end) return;
  Eigen::Vector3d rest[4] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                             Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  ScreenVertex rest_out[4];
  std::copy(points + i, points + end, rest);
  TransformFour(camera, near_plane, rest, rest_out);
  std::copy(rest_out, rest_out + (end - i), out + i);
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
