// Multi-threaded z-buffer rasteriser: depth (camera-frame z), vertex colours and face ids of
// a triangle mesh seen by a pinhole camera. Vertices are moved into the camera frame in
// double precision first, so a scene far from the origin renders as one at the origin.
// Triangles crossing the near plane are clipped. Pixel centres at (x + 0.5, y + 0.5).
//
// Behaviour worth knowing (tested in tests/geometry/rasterizer_test.cc):
// - Depth is the exact camera-frame z of the face's plane at the pixel centre (relative
//   error ~1e-7 against RayCastDepth); coverage uses 1/32768-px fixed point with a
//   top-left rule, so faces sharing an edge leave no crack and never both cover a pixel.
// - Faces with a non-finite vertex are skipped; zero-area faces cover nothing; a face
//   index out of range throws fvs::Error. Ties in depth go to the lower face index, so
//   the result does not depend on num_threads.
// - Colours are perspective-correct (barycentrics of the ray's hit on the face).
// - Images up to 16384 pixels on a side. Each calling thread keeps its scratch buffers
//   (a few MB) for the next call.
#pragma once

#include <cstdint>
#include <vector>

#include "fvs/geometry/camera.h"
#include "fvs/geometry/mesh.h"
#include "fvs/util/image.h"

namespace fvs {

struct RasterizeOptions {
  bool compute_color = false;    // interpolate mesh.colors (must be present)
  bool compute_face_ids = false;
  bool cull_back_faces = false;
  double near_plane = 1e-6;      // camera-frame z below which geometry is clipped
  int num_threads = 0;           // <= 0: DefaultNumThreads()
};

struct RasterResult {
  Image depth;                   // 1 channel, 0 where no surface
  Image color;                   // 3 channels in [0,1] when compute_color
  std::vector<int32_t> face_ids; // width*height, -1 where no surface, when compute_face_ids
};

RasterResult Rasterize(const TriangleMesh& mesh, const PinholeCamera& camera,
                       const RasterizeOptions& options = {});

// Reference: depth by casting one ray per pixel centre through every triangle (slow,
// exact; for tests and the benchmark's accuracy figure). Optionally restricted to rows
// [y0, y1) (other rows are 0). Uses a BVH built per call (its cost grows with the faces); hits
// at any depth > 0 count, faces with a non-finite vertex are skipped, no culling.
Image RayCastDepth(const TriangleMesh& mesh, const PinholeCamera& camera, int y0 = 0,
                   int y1 = -1);

}  // namespace fvs
