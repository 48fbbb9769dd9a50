// The z-buffer rasteriser.
//
// Stages: (1) every vertex goes to the camera frame in double and, when in front of the
// near plane and inside a guard band, to fixed-point pixel coordinates (1/32768 px);
// (2) each thread rasterises runs of faces, taken in order from a shared counter, into
// its own z-buffer (no locks, no face looked at twice); (3) the buffers are merged per
// pixel, the lower face winning ties, so the result is the same as one thread drawing the
// faces in order (first wins); (4) colours are shaded afterwards, once per pixel, from
// the winning face ids.
//
// Coverage uses exact integer edge functions with a top-left rule: two triangles sharing
// an edge never both cover, and never both miss, a pixel centre on it (no cracks). Depth
// does not come from the snapped vertices: each face's plane in the camera frame gives
// 1/z as an affine function of the pixel, evaluated in double, so depth matches a ray
// cast to ~1e-7. Faces with a non-finite vertex are skipped; faces crossing the near
// plane or leaving the guard band are clipped in 3D (double) and their visible part
// rendered.
#include "fvs/geometry/rasterizer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "fvs/geometry/raster_clip.h"
#include "fvs/util/error.h"
#include "fvs/util/parallel.h"

namespace fvs {
namespace {

using raster_internal::ClipPlanes;
using raster_internal::ClipPolygon;
using raster_internal::kGuardPixels;
using raster_internal::kInvalid;
using raster_internal::kNeedsClip;
using raster_internal::kOutsideMask;
using raster_internal::kSubPixel;
using raster_internal::kSubPixelBits;
using raster_internal::Polygon;
using raster_internal::ScreenVertex;
using raster_internal::SnapToFixed;

// One thread's z-buffer (inverse depth, 0 = empty) and face ids.
struct Target {
  float* inverse_depth;
  int32_t* face_ids;  // null when ids are not needed
};

inline int64_t CeilDiv(int64_t a) { return (a + kSubPixel - 1) >> kSubPixelBits; }
inline int64_t FloorDiv(int64_t a) { return a >> kSubPixelBits; }

class Rasterizer {
 public:
  Rasterizer(const TriangleMesh& mesh, const PinholeCamera& camera,
             const RasterizeOptions& options, int num_threads)
      : mesh_(mesh),
        camera_(camera),
        options_(options),
        num_threads_(num_threads),
        width_(camera.width),
        height_(camera.height),
        planes_(raster_internal::MakeClipPlanes(camera, options.near_plane)) {}

  void Run(RasterResult* result);

 private:
  template <bool kWriteIds>
  void RasterizeFaces(int64_t begin, int64_t end, Target target);
  template <bool kWriteIds>
  void ClipAndRasterize(int32_t face, Target target);
  // Pixel centres in [px0, px1] x [py0, py1] (already clipped to the image) covered by
  // the fixed-point triangle.
  template <bool kWriteIds>
  void RasterizeTriangle(int32_t face, int64_t x0, int64_t y0, int64_t x1, int64_t y1,
                         int64_t x2, int64_t y2, int64_t px0, int64_t px1, int64_t py0,
                         int64_t py1, Target target);
  void Merge(int64_t row_begin, int64_t row_end, float* depth);
  // 1/z = a * px + b * py + c at pixel centre (px + 0.5, py + 0.5); false if the plane
  // passes through the camera centre (the face is seen edge-on).
  bool DepthPlane(int32_t face, double* a, double* b, double* c) const;
  void Shade(RasterResult* result) const;
  // Camera-frame position of a vertex, recomputed on demand (cheaper than storing 24
  // bytes per vertex and faulting in fresh pages on every call).
  Eigen::Vector3d CameraVertex(int index) const {
    return raster_internal::ToCameraFrame(camera_, mesh_.vertices[index]);
  }

  const TriangleMesh& mesh_;
  const PinholeCamera& camera_;
  const RasterizeOptions& options_;
  const int num_threads_;
  const int width_, height_;
  const ClipPlanes planes_;
  const Eigen::Vector3d camera_center_ = camera_.Center();
  // (a, b, c) of 1/z = a px + b py + c, per unit of world normal over plane offset.
  const Eigen::Matrix3d plane_from_normal_ = PlaneFromNormal(camera_);
  const float max_inverse_depth_ =
      static_cast<float>(1.0 / options_.near_plane) * 1.0001f;

  static Eigen::Matrix3d PlaneFromNormal(const PinholeCamera& c) {
    Eigen::Matrix3d k_inv;
    k_inv << 1 / c.fx, 0, -c.cx / c.fx, 0, 1 / c.fy, -c.cy / c.fy, 0, 0, 1;
    Eigen::Matrix3d pixel_centre;  // (px, py, 1) -> (px + 0.5, py + 0.5, 1)
    pixel_centre << 1, 0, 0.5, 0, 1, 0.5, 0, 0, 1;
    return (k_inv * pixel_centre).transpose() * c.R;
  }
  // Per calling thread and reused across calls: buffers of a few MB that would otherwise
  // be faulted in page by page on every view.
  struct Scratch {
    std::vector<ScreenVertex> screen;
    std::vector<std::vector<float>> inverse_depth;  // per worker
    std::vector<std::vector<int32_t>> face_ids;     // per worker; [0] holds the merge
  };
  static Scratch& ThreadScratch() {
    static thread_local Scratch scratch;
    return scratch;
  }
  Scratch& scratch_ = ThreadScratch();
  std::vector<ScreenVertex>& screen_ = scratch_.screen;
  std::vector<std::vector<float>>& inverse_depth_ = scratch_.inverse_depth;
  std::vector<std::vector<int32_t>>& face_ids_ = scratch_.face_ids;
  bool want_ids_ = false;
};

bool Rasterizer::DepthPlane(int32_t face, double* a, double* b, double* c) const {
  // The face's plane n.X = n.V0 in world coordinates; in the camera frame its normal is
  // R n and its offset n.(V0 - C), so no vertex needs transforming here. Differences of
  // nearby points first keep a scene far from the origin exact.
  const Eigen::Vector3i& f = mesh_.faces[face];
  const Eigen::Vector3d& v0 = mesh_.vertices[f[0]];
  const Eigen::Vector3d n = (mesh_.vertices[f[1]] - v0).cross(mesh_.vertices[f[2]] - v0);
  const double d = n.dot(v0 - camera_center_);
  if (!(std::abs(d) > 0) || !std::isfinite(d)) return false;
  // Camera points X = z * K^-1 (u, v, 1) on the plane: 1/z = (R n)^T K^-1 (u, v, 1) / d,
  // with u, v at pixel centres (px + 0.5, py + 0.5) folded into plane_from_normal_.
  const Eigen::Vector3d abc = plane_from_normal_ * n * (1.0 / d);
  *a = abc.x();
  *b = abc.y();
  *c = abc.z();
  return std::isfinite(*a) && std::isfinite(*b) && std::isfinite(*c);
}

template <bool kWriteIds>
void Rasterizer::RasterizeTriangle(int32_t face, int64_t x0, int64_t y0, int64_t x1,
                                   int64_t y1, int64_t x2, int64_t y2, int64_t px0,
                                   int64_t px1, int64_t py0, int64_t py1, Target target) {
  // Twice the signed area in the image (y down): positive for faces whose normal points
  // away from the camera, i.e. back faces of a counter-clockwise mesh.
  int64_t area = (x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0);
  if (area == 0) return;  // degenerate after snapping: covers no pixel centre
  if (area > 0 && options_.cull_back_faces) return;
  if (area < 0) {
    std::swap(x1, x2);
    std::swap(y1, y2);
  }
  // The depth plane costs more than the coverage test, and most faces of a dense mesh
  // cover no pixel centre: set it up at the first covered pixel.
  bool have_plane = false;
  double da = 0, db = 0, dc = 0;

  // Edge i runs from vertex i to i+1; inside is E >= 0 (with the tie rule below).
  const int64_t ex[3] = {x1 - x0, x2 - x1, x0 - x2};
  const int64_t ey[3] = {y1 - y0, y2 - y1, y0 - y2};
  const int64_t ox[3] = {x0, x1, x2};
  const int64_t oy[3] = {y0, y1, y2};
  // Top-left rule: a centre exactly on an edge belongs to the face for which the edge
  // goes up (or right when horizontal); the neighbour sees the edge reversed, so exactly
  // one of the two owns it.
  int64_t bias[3];
  for (int i = 0; i < 3; ++i) {
    const bool top_left = ey[i] < 0 || (ey[i] == 0 && ex[i] > 0);
    bias[i] = top_left ? 0 : -1;
  }
  if (px0 == px1 && py0 == py1) {
    // One candidate pixel, the common case for a dense mesh: no loops, no stepping.
    const int64_t fx = px0 * kSubPixel, fy = py0 * kSubPixel;
    for (int i = 0; i < 3; ++i) {
      if (ex[i] * (fy - oy[i]) - ey[i] * (fx - ox[i]) + bias[i] < 0) return;
    }
    if (!DepthPlane(face, &da, &db, &dc)) return;
    const size_t index = static_cast<size_t>(py0) * width_ + px0;
    const float inv_z = static_cast<float>(da * px0 + db * py0 + dc);
    if (inv_z > target.inverse_depth[index] && inv_z <= max_inverse_depth_) {
      target.inverse_depth[index] = inv_z;
      if (kWriteIds) target.face_ids[index] = face;
    }
    return;
  }
  // Edge functions at the first candidate pixel, then stepped exactly (int64) by rows and
  // columns.
  int64_t row_e[3], step_x[3], step_y[3];
  for (int i = 0; i < 3; ++i) {
    row_e[i] =
        ex[i] * (py0 * kSubPixel - oy[i]) - ey[i] * (px0 * kSubPixel - ox[i]) + bias[i];
    step_x[i] = -ey[i] * kSubPixel;
    step_y[i] = ex[i] * kSubPixel;
  }
  if (px1 - px0 < 4 && py1 - py0 < 4) {
    // Boxes of up to 4x4 candidates, nine in ten of the faces that get here on a dense
    // mesh: coverage as a bit mask (bit 4 row + column), computed without branches,
    // whose outcome per pixel is a coin toss for a face of about a pixel.
    const uint32_t row_bits = (1u << (px1 - px0 + 1)) - 1;
    uint32_t mask = 0;
#if defined(__SSE2__)
    // Two columns per 128-bit vector of int64 (exact, as in the scalar code below); the
    // sign bits of the OR of the three edge functions mark the pixels outside.
    using V2 = int64_t __attribute__((vector_size(16)));
    V2 left[3], right[3], down[3];
    for (int i = 0; i < 3; ++i) {
      left[i] = V2{row_e[i], row_e[i] + step_x[i]};
      right[i] = left[i] + 2 * step_x[i];
      down[i] = V2{step_y[i], step_y[i]};
    }
    for (int64_t row = 0; row <= py1 - py0; ++row) {
      const V2 l = left[0] | left[1] | left[2];
      const V2 r = right[0] | right[1] | right[2];
      const uint32_t outside =
          static_cast<uint32_t>(_mm_movemask_pd(reinterpret_cast<__m128d>(l))) |
          static_cast<uint32_t>(_mm_movemask_pd(reinterpret_cast<__m128d>(r))) << 2;
      mask |= (~outside & row_bits) << (4 * row);
      for (int i = 0; i < 3; ++i) {
        left[i] += down[i];
        right[i] += down[i];
      }
    }
#else
    for (int64_t row = 0; row <= py1 - py0; ++row) {
      uint32_t bits = 0;
      for (int column = 0; column < 4; ++column) {
        const int64_t e = (row_e[0] + column * step_x[0]) |
                          (row_e[1] + column * step_x[1]) |
                          (row_e[2] + column * step_x[2]);
        bits |= static_cast<uint32_t>(~static_cast<uint64_t>(e) >> 63) << column;
      }
      mask |= (bits & row_bits) << (4 * row);
      for (int i = 0; i < 3; ++i) row_e[i] += step_y[i];
    }
#endif
    if (mask == 0 || !DepthPlane(face, &da, &db, &dc)) return;
    do {
      const int bit = __builtin_ctz(mask);
      mask &= mask - 1;
      const int64_t px = px0 + (bit & 3), py = py0 + (bit >> 2);
      const size_t index = static_cast<size_t>(py) * width_ + px;
      const float inv_z = static_cast<float>(da * static_cast<double>(px) +
                                             (db * static_cast<double>(py) + dc));
      if (inv_z > target.inverse_depth[index] && inv_z <= max_inverse_depth_) {
        target.inverse_depth[index] = inv_z;
        if (kWriteIds) target.face_ids[index] = face;
      }
    } while (mask != 0);
    return;
  }
  for (int64_t py = py0; py <= py1; ++py) {
    int64_t e[3] = {row_e[0], row_e[1], row_e[2]};
    const int64_t* step = step_x;
    for (int i = 0; i < 3; ++i) row_e[i] += step_y[i];
    float* depth_row = target.inverse_depth + py * width_;
    int32_t* id_row = kWriteIds ? target.face_ids + py * width_ : nullptr;
    double row_c = db * static_cast<double>(py) + dc;
    bool entered = false;
    for (int64_t px = px0; px <= px1; ++px) {
      if ((e[0] | e[1] | e[2]) < 0) {
        if (entered) break;  // a triangle meets a row in one span
      } else {
        entered = true;
        if (!have_plane) {
          if (!DepthPlane(face, &da, &db, &dc)) return;
          have_plane = true;
          row_c = db * static_cast<double>(py) + dc;
        }
        const float inv_z = static_cast<float>(da * static_cast<double>(px) + row_c);
        if (inv_z > depth_row[px] && inv_z <= max_inverse_depth_) {
          depth_row[px] = inv_z;
          if (kWriteIds) id_row[px] = face;
        }
      }
      e[0] += step[0];
      e[1] += step[1];
      e[2] += step[2];
    }
  }
}

template <bool kWriteIds>
void Rasterizer::ClipAndRasterize(int32_t face, Target target) {
  const Eigen::Vector3i& f = mesh_.faces[face];
  Polygon polygon;
  polygon.size = 3;
  for (int k = 0; k < 3; ++k) polygon.v[k] = CameraVertex(f[k]);
  ClipPolygon(planes_, &polygon);
  if (polygon.size < 3) return;
  int32_t x[Polygon::kMaxVertices], y[Polygon::kMaxVertices];
  for (int k = 0; k < polygon.size; ++k) {
    // Clipping left every point inside the guard band; a failure here means a rounding
    // excursion on a tiny sliver, which covers nothing.
    if (!SnapToFixed(camera_, polygon.v[k], &x[k], &y[k])) return;
  }
  for (int k = 1; k + 1 < polygon.size; ++k) {
    const int64_t py0 = std::max<int64_t>(CeilDiv(std::min({y[0], y[k], y[k + 1]})), 0);
    const int64_t py1 =
        std::min<int64_t>(FloorDiv(std::max({y[0], y[k], y[k + 1]})), height_ - 1);
    const int64_t px0 = std::max<int64_t>(CeilDiv(std::min({x[0], x[k], x[k + 1]})), 0);
    const int64_t px1 =
        std::min<int64_t>(FloorDiv(std::max({x[0], x[k], x[k + 1]})), width_ - 1);
    if (py0 > py1 || px0 > px1) continue;
    RasterizeTriangle<kWriteIds>(face, x[0], y[0], x[k], y[k], x[k + 1], y[k + 1], px0,
                                 px1, py0, py1, target);
  }
}

template <bool kWriteIds>
void Rasterizer::RasterizeFaces(int64_t begin, int64_t end, Target target) {
  const Eigen::Vector3i* faces = mesh_.faces.data();
  const ScreenVertex* screen = screen_.data();
  const uint32_t num_vertices = static_cast<uint32_t>(mesh_.vertices.size());
  const int64_t max_row = height_ - 1, max_column = width_ - 1;
  for (int64_t i = begin; i < end; ++i) {
    const Eigen::Vector3i& f = faces[i];
    // Negative indices wrap to huge unsigned values.
    if (static_cast<uint32_t>(f[0]) >= num_vertices ||
        static_cast<uint32_t>(f[1]) >= num_vertices ||
        static_cast<uint32_t>(f[2]) >= num_vertices) {
      throw Error("Rasterize",
                  "face " + std::to_string(i) + " refers to a vertex index out of range");
    }
    const ScreenVertex& a = screen[f[0]];
    const ScreenVertex& b = screen[f[1]];
    const ScreenVertex& c = screen[f[2]];
    const uint32_t any = a.code | b.code | c.code;
    if (any & kInvalid) continue;
    if (a.code & b.code & c.code & kOutsideMask) continue;
    if (any & kNeedsClip) {
      ClipAndRasterize<kWriteIds>(static_cast<int32_t>(i), target);
      continue;
    }
    // Most faces of a dense mesh have no pixel centre in their bounding box: reject them
    // before any set-up.
    const int64_t py0 = std::max<int64_t>(CeilDiv(std::min({a.y, b.y, c.y})), 0);
    const int64_t py1 = std::min(FloorDiv(std::max({a.y, b.y, c.y})), max_row);
    if (py0 > py1) continue;
    const int64_t px0 = std::max<int64_t>(CeilDiv(std::min({a.x, b.x, c.x})), 0);
    const int64_t px1 = std::min(FloorDiv(std::max({a.x, b.x, c.x})), max_column);
    if (px0 > px1) continue;
    RasterizeTriangle<kWriteIds>(static_cast<int32_t>(i), a.x, a.y, b.x, b.y, c.x, c.y,
                                 px0, px1, py0, py1, target);
  }
}

void Rasterizer::Merge(int64_t row_begin, int64_t row_end, float* depth) {
  const size_t begin = static_cast<size_t>(row_begin) * width_;
  const size_t end = static_cast<size_t>(row_end) * width_;
  float* best = inverse_depth_[0].data();
  int32_t* best_id = want_ids_ ? face_ids_[0].data() : nullptr;
  // Depth only: the last buffer is folded into the output pass (which of two faces at
  // equal depth wins does not change the depth), one pass over the image fewer.
  const int folded = best_id ? num_threads_ : num_threads_ - 1;
  for (int t = 1; t < folded; ++t) {
    const float* other = inverse_depth_[t].data();
    const int32_t* other_id = best_id ? face_ids_[t].data() : nullptr;
    if (best_id) {
      for (size_t i = begin; i < end; ++i) {
        // Equal depth: the lower face wins, as when one thread draws all faces in order.
        // (Empty pixels, 0 and id -1 in both buffers, stay as they are.)
        if (other[i] > best[i] || (other[i] == best[i] && other_id[i] < best_id[i])) {
          best[i] = other[i];
          best_id[i] = other_id[i];
        }
      }
    } else {
      for (size_t i = begin; i < end; ++i) best[i] = std::max(best[i], other[i]);
    }
  }
  const float* last =
      folded < num_threads_ ? inverse_depth_[num_threads_ - 1].data() : best;
  for (size_t i = begin; i < end; ++i) {
    const float inverse = std::max(best[i], last[i]);
    // 1/x in float is 1/x in double rounded to float (a float quotient rounded twice is
    // rounded once: 53 >= 2 x 24 + 2), at a quarter of the cost. Beyond float range (a
    // surface ~1e38 away) counts as no surface, never as Inf.
    const float z = 1.0f / inverse;
    depth[i] = inverse > 0 && z < std::numeric_limits<float>::infinity() ? z : 0.0f;
  }
}

void Rasterizer::Run(RasterResult* result) {
  const int64_t num_vertices = static_cast<int64_t>(mesh_.vertices.size());
  const int64_t num_faces = static_cast<int64_t>(mesh_.faces.size());
  screen_.resize(num_vertices);
  ParallelForRanges(
      0, num_vertices,
      [&](int64_t b, int64_t e, int) {
        raster_internal::TransformToScreen(camera_, options_.near_plane,
                                           mesh_.vertices.data(), b, e, screen_.data());
      },
      num_threads_);

  const size_t num_pixels = static_cast<size_t>(width_) * height_;
  want_ids_ = options_.compute_face_ids || options_.compute_color;
  inverse_depth_.resize(num_threads_);
  face_ids_.resize(num_threads_);
  constexpr int64_t kMinChunk = 512;
  std::atomic<int64_t> next_face{0};
  ParallelForRanges(
      0, num_threads_,
      [&](int64_t t, int64_t, int) {
        // Each worker clears and fills its own buffers (first touch on its own core).
        inverse_depth_[t].assign(num_pixels, 0.0f);
        if (want_ids_) face_ids_[t].assign(num_pixels, -1);
        // The output is allocated (and zero-filled) here rather than after this phase:
        // the other workers take over faces meanwhile, so it costs half as much.
        if (t == 0) result->depth = Image(width_, height_, 1);
        const Target target{inverse_depth_[t].data(),
                            want_ids_ ? face_ids_[t].data() : nullptr};
        // Guided self-scheduling: chunks of a shrinking share of the faces left, taken
        // in increasing order, so each thread still draws its faces in order (the first
        // of equal depth wins) and mostly in long contiguous runs (the z-buffer lines a
        // run touches are the ones its neighbour faces touch). Equal halves were up to
        // 2x unbalanced: a view's cost is far from uniform over the face list.
        while (true) {
          int64_t begin = next_face.load(std::memory_order_relaxed), end = 0;
          do {
            const int64_t left = num_faces - begin;
            if (left <= 0) return;
            end = begin + std::max<int64_t>(left / (2 * num_threads_), kMinChunk);
            end = std::min(end, num_faces);
          } while (
              !next_face.compare_exchange_weak(begin, end, std::memory_order_relaxed));
          if (want_ids_) {
            RasterizeFaces<true>(begin, end, target);
          } else {
            RasterizeFaces<false>(begin, end, target);
          }
        }
      },
      num_threads_);

  ParallelForRanges(
      0, height_,
      [&](int64_t b, int64_t e, int) { Merge(b, e, result->depth.data.data()); },
      num_threads_);
  if (options_.compute_color) Shade(result);
  if (options_.compute_face_ids) result->face_ids = face_ids_[0];
}

// Perspective-correct colour: the barycentric coordinates of the point where the pixel's
// ray meets the winning face (in the camera frame, double), clamped to the face.
void Rasterizer::Shade(RasterResult* result) const {
  result->color = Image(width_, height_, 3);
  ParallelFor(
      0, height_,
      [&](int64_t py) {
        for (int px = 0; px < width_; ++px) {
          const int32_t face = face_ids_[0][py * width_ + px];
          if (face < 0) continue;
          const Eigen::Vector3i& f = mesh_.faces[face];
          const Eigen::Vector3d v0 = CameraVertex(f[0]);
          const Eigen::Vector3d e1 = CameraVertex(f[1]) - v0;
          const Eigen::Vector3d e2 = CameraVertex(f[2]) - v0;
          const Eigen::Vector3d dir((px + 0.5 - camera_.cx) / camera_.fx,
                                    (py + 0.5 - camera_.cy) / camera_.fy, 1.0);
          const Eigen::Vector3d p = dir.cross(e2);
          const double det = e1.dot(p);
          double b1 = 1.0 / 3, b2 = 1.0 / 3;
          if (std::abs(det) > 0) {
            const Eigen::Vector3d s = -v0;
            const Eigen::Vector3d q = s.cross(e1);
            b1 = s.dot(p) / det;
            b2 = dir.dot(q) / det;
          }
          if (!std::isfinite(b1) || !std::isfinite(b2)) b1 = b2 = 1.0 / 3;
          b1 = std::clamp(b1, 0.0, 1.0);
          b2 = std::clamp(b2, 0.0, 1.0);
          if (b1 + b2 > 1) {
            const double sum = b1 + b2;
            b1 /= sum;
            b2 /= sum;
          }
          const double b0 = 1.0 - b1 - b2;
          float* out = &result->color.at(px, static_cast<int>(py));
          for (int k = 0; k < 3; ++k) {
            const double c = b0 * mesh_.colors[f[0]][k] + b1 * mesh_.colors[f[1]][k] +
                             b2 * mesh_.colors[f[2]][k];
            out[k] = static_cast<float>(std::clamp(c / 255.0, 0.0, 1.0));
          }
        }
      },
      num_threads_);
}

}  // namespace

RasterResult Rasterize(const TriangleMesh& mesh, const PinholeCamera& camera,
                       const RasterizeOptions& options) {
  if (!camera.IsValid()) throw Error("Rasterize", "invalid camera");
  if (camera.width > raster_internal::kMaxImageSide ||
      camera.height > raster_internal::kMaxImageSide) {
    throw Error("Rasterize", "image larger than 16384 pixels on a side");
  }
  if (!(options.near_plane > 0) || !std::isfinite(options.near_plane)) {
    throw Error("Rasterize", "near_plane must be positive and finite");
  }
  if (options.compute_color && mesh.colors.size() != mesh.vertices.size()) {
    throw Error("Rasterize", "compute_color needs one colour per vertex");
  }
  if (mesh.vertices.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max()) ||
      mesh.faces.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    throw Error("Rasterize", "mesh too large");
  }
  int num_threads = options.num_threads > 0 ? options.num_threads : DefaultNumThreads();
  num_threads = std::clamp(num_threads, 1, 255);
  RasterResult result;
  Rasterizer rasterizer(mesh, camera, options, num_threads);
  rasterizer.Run(&result);
  return result;
}

}  // namespace fvs
