// Internal to the rasteriser: the vertex transform, fixed-point snapping and clipping of
// faces against the near plane and a guard band around the image, in the camera frame
// (double).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "fvs/geometry/camera.h"

namespace fvs::raster_internal {

// 1/32768 pixel: snapping moves a vertex by at most 1.5e-5 px, so coverage differs from
// an exact ray cast only for pixel centres that close to an edge. With the guard band and
// the largest image below, coordinates stay under 2^30 and edge functions (a difference
// of two products of coordinate differences) under 2^62: exact in int64.
constexpr int kSubPixelBits = 15;
constexpr int64_t kSubPixel = int64_t{1} << kSubPixelBits;
// Vertices projecting further than this outside the image are clipped in 3D instead.
constexpr double kGuardPixels = 4096.0;
// Largest image side the fixed-point range allows.
constexpr int kMaxImageSide = 16384;

// Camera-frame position of a world point, the sums written out in one order: the
// four-wide transform below computes the very same roundings, so a vertex snapped there
// and the same vertex snapped again on the clipping path land on the same fixed point.
inline Eigen::Vector3d ToCameraFrame(const PinholeCamera& c, const Eigen::Vector3d& p) {
  const Eigen::Matrix3d& r = c.R;
  return {r(0, 0) * p.x() + r(0, 1) * p.y() + r(0, 2) * p.z() + c.t.x(),
          r(1, 0) * p.x() + r(1, 1) * p.y() + r(1, 2) * p.z() + c.t.y(),
          r(2, 0) * p.x() + r(2, 1) * p.y() + r(2, 2) * p.z() + c.t.z()};
}

// Fixed-point pixel position of a camera-frame point with z > 0, pixel centre (px, py) at
// (px, py) * kSubPixel. False when it falls outside the guard band. Not inlined, so that
// every caller rounds a vertex exactly the same way (shared edges must snap identically).
bool SnapToFixed(const PinholeCamera& camera, const Eigen::Vector3d& p, int32_t* x,
                 int32_t* y);

enum VertexCode : uint32_t {
  kLeft = 1,
  kRight = 2,
  kTop = 4,
  kBottom = 8,
  kBehind = 16,
  kOutsideMask = 31,
  kNeedsClip = 32,  // behind the near plane or outside the guard band: no fixed point
  kInvalid = 64,    // non-finite (no other bit set)
};

struct ScreenVertex {
  int32_t x = 0, y = 0;  // fixed point, pixel centre (px, py) at (px, py) * kSubPixel
  uint32_t code = 0;  // VertexCode bits; x, y are 0 unless the code is below kNeedsClip
};

// Screen vertices of world points [begin, end), four at a time (the transform is a fifth
// of a depth view's time in scalar code). Per vertex equal to
// SnapToFixed(ToCameraFrame()) with the frustum codes: kLeft etc. when outside that side
// of the image (for any z).
void TransformToScreen(const PinholeCamera& camera, double near_plane,
                       const Eigen::Vector3d* points, int64_t begin, int64_t end,
                       ScreenVertex* out);

// Half-spaces n.p + d >= 0 in the camera frame: the near plane, then the four sides of
// the guard band (half the snapping guard, so clipped points always snap).
struct ClipPlanes {
  std::array<Eigen::Vector4d, 5> planes;
};
ClipPlanes MakeClipPlanes(const PinholeCamera& camera, double near_plane);

struct Polygon {
  static constexpr int kMaxVertices = 12;  // a triangle cut by 5 planes has at most 8
  std::array<Eigen::Vector3d, kMaxVertices> v;
  int size = 0;
};

// Sutherland-Hodgman. An edge is cut at a point computed from its endpoints in a fixed
// (lexicographic) order, so two faces sharing the edge get the very same point.
void ClipPolygon(const ClipPlanes& planes, Polygon* polygon);

}  // namespace fvs::raster_internal
