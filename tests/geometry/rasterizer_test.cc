#include "fvs/geometry/rasterizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fvs/geometry/raster_clip.h"
#include "fvs/util/error.h"
#include "geometry/geometry_test_util.h"

namespace fvs {
namespace {

using testing::LookAtCamera;
using testing::MakeBox;
using testing::MakeRandomSoup;
using testing::MakeSphere;

struct Comparison {
  int64_t covered_both = 0;
  int64_t coverage_differs = 0;
  double max_relative_error = 0;
  int64_t above_1e5 = 0;  // pixels with relative depth error above 1e-5
};

Comparison CompareDepth(const Image& a, const Image& b) {
  Comparison c;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const bool ca = a.data[i] > 0, cb = b.data[i] > 0;
    if (ca != cb) {
      ++c.coverage_differs;
    } else if (ca) {
      ++c.covered_both;
      const double rel = std::abs(a.data[i] - b.data[i]) / b.data[i];
      c.max_relative_error = std::max(c.max_relative_error, rel);
      if (rel > 1e-5) ++c.above_1e5;
    }
  }
  return c;
}

bool AllFinite(const Image& image) {
  for (float v : image.data) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

TEST(RasterizerTest, MatchesRayCastOnRandomSoupsAndCameras) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 8; ++trial) {
    const TriangleMesh mesh = MakeRandomSoup(300, 0.4, rng);
    const Eigen::Vector3d eye =
        Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * 3.5;
    PinholeCamera camera =
        LookAtCamera(eye, Eigen::Vector3d(0.2 * u(rng), 0.2 * u(rng), 0),
                     Eigen::Vector3d(0, 0, 1), 160 + trial * 7, 120, 150);
    camera.cx += 3.3 * u(rng);  // off-centre principal point, different fx and fy
    camera.fy *= 1.1;
    RasterizeOptions options;
    options.num_threads = 1 + trial % 3;
    const RasterResult raster = Rasterize(mesh, camera, options);
    const Image reference = RayCastDepth(mesh, camera);
    ASSERT_EQ(raster.depth.width, camera.width);
    ASSERT_EQ(raster.depth.height, camera.height);
    const Comparison c = CompareDepth(raster.depth, reference);
    SCOPED_TRACE(trial);
    EXPECT_GT(c.covered_both, camera.width * camera.height / 10);
    // Coverage may differ only where a pixel centre lies within snapping distance
    // (1/32768 px) of an edge; depth may differ where two faces intersect.
    EXPECT_LE(c.coverage_differs, 2);
    EXPECT_LE(c.above_1e5, 2);
    EXPECT_TRUE(AllFinite(raster.depth));
  }
}

// The vectorised transform (an AVX2 or SSE2 clone) must snap every vertex exactly as the
// scalar SnapToFixed does on the clipping path, or faces sharing an edge with a clipped
// face would crack. Points near the guard band, the near plane, at rounding ties, far
// away, behind the camera and non-finite.
TEST(RasterizerTest, VectorTransformSnapsAsTheScalarPath) {
  using namespace raster_internal;  // NOLINT
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d centre(1e4 * (trial % 3), 3 * unit(rng), unit(rng));
    const PinholeCamera camera = LookAtCamera(
        centre, centre + Eigen::Vector3d(unit(rng), unit(rng), 4),
        Eigen::Vector3d(0, -1, 0), 97 + trial, 61 + 3 * trial, 80 + 40 * trial);
    const double near_plane = trial % 2 ? 1e-6 : 0.5;
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 4001; ++i) {  // not a multiple of four: the tail path too
      const double depth = std::pow(10.0, 4 * unit(rng));
      const Eigen::Vector3d ray((unit(rng) * 40 * camera.width) / camera.fx,
                                (unit(rng) * 40 * camera.height) / camera.fy, 1);
      const Eigen::Vector3d in_camera = (i % 7 == 0 ? -1 : 1) * depth * ray;
      points.push_back(camera.R.transpose() * (in_camera - camera.t));
    }
    // Ties: pixel coordinates on a 1/65536 grid round half to even.
    for (int i = 0; i < 64; ++i) {
      const double u = std::floor(unit(rng) * 50 + 48) + (i % 4) / 65536.0 + 0.5;
      const Eigen::Vector3d in_camera(((u - camera.cx) / camera.fx) * 2, 0.5, 2);
      points.push_back(camera.R.transpose() * (in_camera - camera.t));
    }
    const double inf = std::numeric_limits<double>::infinity();
    points.push_back(Eigen::Vector3d(std::nan(""), 0, 1));
    points.push_back(Eigen::Vector3d(0, inf, 1));
    points.push_back(camera.Center());
    std::vector<ScreenVertex> screen(points.size());
    TransformToScreen(camera, near_plane, points.data(), 0, points.size(), screen.data());
    int snapped = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      SCOPED_TRACE("trial " + std::to_string(trial) + " point " + std::to_string(i));
      const Eigen::Vector3d p = ToCameraFrame(camera, points[i]);
      if (!p.allFinite()) {
        EXPECT_EQ(screen[i].code, kInvalid);
        continue;
      }
      int32_t x = 0, y = 0;
      const bool behind = p.z() < near_plane;
      const bool ok = !behind && SnapToFixed(camera, p, &x, &y);
      EXPECT_EQ(screen[i].code & kBehind, behind ? kBehind : 0u);
      EXPECT_EQ((screen[i].code & kNeedsClip) == 0, ok);
      if (ok) {
        ++snapped;
        EXPECT_EQ(screen[i].x, x);
        EXPECT_EQ(screen[i].y, y);
      }
      const double u = camera.fx * p.x() + camera.cx * p.z();
      EXPECT_EQ((screen[i].code & kLeft) != 0, u < 0);
    }
    EXPECT_GT(snapped, 1000);
  }
}

TEST(RasterizerTest, ThreadCountDoesNotChangeTheResult) {
  std::mt19937 rng(3);
  const TriangleMesh mesh = MakeRandomSoup(2000, 0.3, rng);
  const PinholeCamera camera =
      LookAtCamera({0, -3, 0.5}, {0, 0, 0}, {0, 0, 1}, 200, 150, 180);
  RasterizeOptions options;
  options.compute_face_ids = true;
  options.num_threads = 1;
  const RasterResult one = Rasterize(mesh, camera, options);
  for (int threads : {2, 3, 7}) {
    options.num_threads = threads;
    const RasterResult many = Rasterize(mesh, camera, options);
    EXPECT_EQ(one.depth.data, many.depth.data);
    EXPECT_EQ(one.face_ids, many.face_ids);
  }
}

// A floor plane reaching from behind the camera to far ahead: its two triangles cross the
// near plane and must be clipped, not dropped. Depth is known in closed form.
TEST(RasterizerTest, ClipsFacesCrossingTheNearPlane) {
  TriangleMesh floor;
  const double h = 1.5, extent = 200;
  floor.vertices = {{-extent, h, -extent},
                    {extent, h, -extent},
                    {extent, h, extent},
                    {-extent, h, extent}};
  floor.faces = {{0, 1, 2}, {0, 2, 3}};
  PinholeCamera camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx = camera.fy = 40;
  camera.cx = 31.7;
  camera.cy = 24;  // horizon exactly between rows 23 and 24
  for (double near : {1e-6, 0.01, 1.0}) {
    RasterizeOptions options;
    options.near_plane = near;
    const Image depth = Rasterize(floor, camera, options).depth;
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        const double ray_y = (y + 0.5 - camera.cy) / camera.fy;
        const double expected = ray_y > 0 ? h / ray_y : 0;
        if (expected > extent * 0.9) continue;  // near the far edge
        if (expected > 0 && expected < near) {
          EXPECT_EQ(depth.at(x, y), 0) << x << " " << y;
          continue;
        }
        ASSERT_NEAR(depth.at(x, y), expected, 1e-6 * expected) << x << " " << y;
      }
    }
  }
  // Camera looking straight down at the floor from above, floor all around it.
  const PinholeCamera down = LookAtCamera({0, 0, 0}, {0, h, 0}, {0, 0, 1}, 40, 30, 20);
  const Image depth = Rasterize(floor, down).depth;
  for (int y = 0; y < down.height; ++y) {
    for (int x = 0; x < down.width; ++x) {
      ASSERT_NEAR(depth.at(x, y), h, 1e-6 * h);
    }
  }
}

// Inside a closed room every pixel sees a wall; walls behind and beside the camera cross
// the near plane and the guard band, so this exercises clipping without cracks.
TEST(RasterizerTest, RoomSeenFromInsideHasNoHoles) {
  const TriangleMesh room = MakeBox({-3, -2, -4}, {5, 2.5, 3}, 6, /*inward=*/true);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 6; ++trial) {
    const Eigen::Vector3d eye(u(rng), u(rng), u(rng));
    const PinholeCamera camera =
        LookAtCamera(eye, eye + Eigen::Vector3d(u(rng), u(rng), u(rng)),
                     Eigen::Vector3d(0, 0.3, 1), 120, 90, 40 + 30 * trial);
    RasterizeOptions options;
    options.cull_back_faces = true;  // walls face inward, towards the camera
    const Image depth = Rasterize(room, camera, options).depth;
    const Image reference = RayCastDepth(room, camera);
    for (size_t i = 0; i < depth.data.size(); ++i) {
      ASSERT_GT(depth.data[i], 0) << "hole at pixel " << i << " trial " << trial;
    }
    const Comparison c = CompareDepth(depth, reference);
    EXPECT_EQ(c.coverage_differs, 0);
    EXPECT_LT(c.max_relative_error, 1e-6);
  }
}

TEST(RasterizerTest, BackFaceCulling) {
  TriangleMesh facing;  // counter-clockwise seen from the camera at the origin
  facing.vertices = {{-1, -1, 5}, {-1, 1, 5}, {1, -1, 5}};
  facing.faces = {{0, 1, 2}};
  const Eigen::Vector3d n = (facing.vertices[1] - facing.vertices[0])
                                .cross(facing.vertices[2] - facing.vertices[0]);
  ASSERT_LT(n.z(), 0);  // normal towards the camera
  TriangleMesh away = facing;
  away.faces = {{0, 2, 1}};
  PinholeCamera camera;
  camera.width = camera.height = 32;
  camera.fx = camera.fy = 30;
  camera.cx = camera.cy = 16;
  RasterizeOptions cull;
  cull.cull_back_faces = true;
  auto covered = [](const Image& d) {
    int n = 0;
    for (float v : d.data) n += v > 0;
    return n;
  };
  const int full = covered(Rasterize(facing, camera).depth);
  EXPECT_GT(full, 50);
  EXPECT_EQ(covered(Rasterize(away, camera).depth), full);
  EXPECT_EQ(covered(Rasterize(facing, camera, cull).depth), full);
  EXPECT_EQ(covered(Rasterize(away, camera, cull).depth), 0);
  // A closed sphere shows its front half either way.
  const TriangleMesh sphere = MakeSphere(3, 1.0, {0.1, 0, 4});
  EXPECT_EQ(Rasterize(sphere, camera, cull).depth.data,
            Rasterize(sphere, camera).depth.data);
}

// Colours affine in world position are interpolated exactly by perspective-correct
// barycentrics, on a plane strongly slanted in depth.
TEST(RasterizerTest, PerspectiveCorrectColour) {
  TriangleMesh quad;
  quad.vertices = {{-2, -1, 2}, {2, -1, 2}, {2, 1, 12}, {-2, 1, 12}};
  quad.faces = {{0, 2, 1}, {0, 3, 2}};
  auto color_of = [](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(255 * (p.x() + 2) / 4, 255 * (p.z() - 2) / 10, 77);
  };
  for (const auto& p : quad.vertices) {
    const Eigen::Vector3d c = color_of(p);
    quad.colors.emplace_back(c.x(), c.y(), c.z());
  }
  PinholeCamera camera = testing::CenteredCamera(80, 60, 50);
  RasterizeOptions options;
  options.compute_color = true;
  const RasterResult r = Rasterize(quad, camera, options);
  ASSERT_EQ(r.color.channels, 3);
  int checked = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const float d = r.depth.at(x, y);
      if (d == 0) {
        for (int k = 0; k < 3; ++k) EXPECT_EQ(r.color.at(x, y, k), 0);
        continue;
      }
      const Eigen::Vector3d p = camera.PixelToCamera(x + 0.5, y + 0.5, d);
      const Eigen::Vector3d expected = color_of(p) / 255.0;
      for (int k = 0; k < 3; ++k) {
        ASSERT_NEAR(r.color.at(x, y, k), expected[k], 2e-5) << x << " " << y << " " << k;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  // Affine (screen-space) interpolation would be off by far more than the tolerance here.
  const float mid = r.color.at(40, 30, 1);
  EXPECT_GT(std::abs(mid - 0.5f), 0.02f);
}

// A plane covering the whole image cut into many small triangles, some with vertices
// exactly on pixel centres and edges through them. Split into two halves rendered
// separately, the halves must cover disjoint pixel sets whose union is the whole image:
// no cracks, no pixel drawn twice.
TEST(RasterizerTest, SharedEdgesHaveNoCracksAndNoDoubleCoverage) {
  PinholeCamera camera = testing::CenteredCamera(96, 64, 100);
  std::mt19937 rng(9);
  for (bool jitter : {false, true}) {
    // Grid vertices at pixel positions of the image plane at depth 1 (pixel-centre hits).
    const int n = 24;
    TriangleMesh grid;
    // Spacing is 4.7 px; jitter below a quarter of it keeps every triangle unfolded.
    std::uniform_real_distribution<double> j(-1.1, 1.1);
    for (int gy = 0; gy <= n; ++gy) {
      for (int gx = 0; gx <= n; ++gx) {
        double px = -8 + gx * (camera.width + 16) / double(n);
        double py = -8 + gy * (camera.height + 16) / double(n);
        if (jitter && gx > 0 && gx < n && gy > 0 && gy < n) {
          px += j(rng);
          py += j(rng);
        } else {
          px = std::round(px) + 0.5;
          py = std::round(py) + 0.5;
        }
        const double depth = 1.0 + 0.01 * gx;
        grid.vertices.push_back(camera.PixelToCamera(px, py, depth));
      }
    }
    for (int gy = 0; gy < n; ++gy) {
      for (int gx = 0; gx < n; ++gx) {
        const int a = gy * (n + 1) + gx, b = a + 1, c = a + n + 2, d = a + n + 1;
        if ((gx + gy) % 3 == 0) {
          grid.faces.push_back({a, b, c});
          grid.faces.push_back({a, c, d});
        } else {
          grid.faces.push_back({a, b, d});
          grid.faces.push_back({b, c, d});
        }
      }
    }
    TriangleMesh half[2] = {grid, grid};
    half[0].faces.clear();
    half[1].faces.clear();
    std::bernoulli_distribution coin(0.5);
    for (const auto& f : grid.faces) half[coin(rng)].faces.push_back(f);
    const Image d0 = Rasterize(half[0], camera).depth;
    const Image d1 = Rasterize(half[1], camera).depth;
    const Image all = Rasterize(grid, camera).depth;
    for (size_t i = 0; i < all.data.size(); ++i) {
      ASSERT_GT(all.data[i], 0) << "crack at pixel " << i;
      ASSERT_NE(d0.data[i] > 0, d1.data[i] > 0) << "pixel " << i << " jitter " << jitter;
    }
  }
}

TEST(RasterizerTest, ClosedSphereHasNoHolesAndMatchesTheAnalyticSphere) {
  const Eigen::Vector3d center(0.3, -0.2, 6);
  const double radius = 2;
  const TriangleMesh sphere = MakeSphere(5, radius, center);  // 20480 faces
  PinholeCamera camera = testing::CenteredCamera(160, 120, 100);
  const Image depth = Rasterize(sphere, camera).depth;
  // A pixel whose ray passes well inside the inscribed (chord) radius must be covered.
  const double inscribed = radius * std::cos(0.05);
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d d = camera.PixelToCamera(x + 0.5, y + 0.5, 1).normalized();
      const double distance = (center - center.dot(d) * d).norm();
      if (distance < inscribed) {
        ASSERT_GT(depth.at(x, y), 0) << x << " " << y;
      } else if (distance > radius) {
        ASSERT_EQ(depth.at(x, y), 0) << x << " " << y;
      }
    }
  }
}

TEST(RasterizerTest, FarFromTheOriginRendersAsAtTheOrigin) {
  const TriangleMesh sphere = MakeSphere(4, 1.0, {0, 0, 0});
  std::mt19937 rng(2);
  const TriangleMesh soup = MakeRandomSoup(200, 0.5, rng);
  for (const TriangleMesh* mesh : {&sphere, &soup}) {
    const PinholeCamera camera =
        LookAtCamera({0.3, -2.5, 1.1}, {0, 0, 0}, {0, 0, 1}, 128, 96, 110);
    const Eigen::Vector3d shift(1e4, 1e4, 1e4);
    TriangleMesh far = *mesh;
    for (auto& v : far.vertices) v += shift;
    PinholeCamera far_camera = camera;
    far_camera.t = -far_camera.R * (camera.Center() + shift);
    const Image near_depth = Rasterize(*mesh, camera).depth;
    const Image far_depth = Rasterize(far, far_camera).depth;
    const Comparison c = CompareDepth(far_depth, near_depth);
    EXPECT_GT(c.covered_both, 1000);
    EXPECT_EQ(c.coverage_differs, 0);
    EXPECT_LT(c.max_relative_error, 1e-6);
  }
}

TEST(RasterizerTest, EmptyAwayDegenerateAndNonFinite) {
  PinholeCamera camera = testing::CenteredCamera(40, 30, 30);
  RasterizeOptions options;
  options.compute_color = true;
  options.compute_face_ids = true;
  // Empty mesh.
  TriangleMesh empty;
  RasterResult r = Rasterize(empty, camera, options);
  EXPECT_EQ(r.depth.data, std::vector<float>(40 * 30, 0.0f));
  EXPECT_EQ(r.color.data.size(), 40u * 30 * 3);
  EXPECT_EQ(r.face_ids, std::vector<int32_t>(40 * 30, -1));
  // Camera looking away from a sphere.
  TriangleMesh sphere = MakeSphere(2, 1.0, {0, 0, -5});
  sphere.colors.assign(sphere.vertices.size(), Vector3ub(255, 0, 0));
  r = Rasterize(sphere, camera, options);
  EXPECT_EQ(r.depth.data, std::vector<float>(40 * 30, 0.0f));
  // Degenerate faces: repeated vertex, collinear points, all points equal.
  TriangleMesh degenerate;
  degenerate.vertices = {{-1, -1, 3}, {1, 1, 3}, {0, 0, 3}, {2, 2, 3}, {0.5, -0.5, 3}};
  degenerate.colors.assign(5, Vector3ub(9, 9, 9));
  degenerate.faces = {{0, 1, 2}, {0, 0, 1}, {2, 2, 2}, {0, 2, 3}};
  r = Rasterize(degenerate, camera, options);
  EXPECT_EQ(r.depth.data, std::vector<float>(40 * 30, 0.0f));
  // A good face among them renders normally.
  degenerate.faces.push_back({0, 4, 1});
  r = Rasterize(degenerate, camera, options);
  int covered = 0;
  for (size_t i = 0; i < r.depth.data.size(); ++i) {
    if (r.depth.data[i] > 0) {
      ++covered;
      EXPECT_NEAR(r.depth.data[i], 3.0, 3e-6);
      EXPECT_EQ(r.face_ids[i], 4);
    }
  }
  EXPECT_GT(covered, 30);
  // A non-finite vertex: its faces are skipped (documented), the others still render.
  TriangleMesh bad = degenerate;
  bad.vertices.push_back({std::nan(""), 0, 3});
  bad.vertices.push_back({0, std::numeric_limits<double>::infinity(), 3});
  bad.colors.resize(bad.vertices.size());
  bad.faces.push_back({5, 0, 4});
  bad.faces.push_back({0, 6, 1});
  const RasterResult rb = Rasterize(bad, camera, options);
  EXPECT_EQ(rb.depth.data, r.depth.data);
  EXPECT_TRUE(AllFinite(rb.depth));
  EXPECT_TRUE(AllFinite(rb.color));
  // The reference skips them as well.
  EXPECT_EQ(RayCastDepth(bad, camera).data, RayCastDepth(degenerate, camera).data);
}

TEST(RasterizerTest, FaceIdsAgreeWithDepth) {
  const TriangleMesh sphere = MakeSphere(3, 1.0, {0, 0, 4});
  PinholeCamera camera;
  camera.width = 64;
  camera.height = 64;
  camera.fx = camera.fy = 60;
  camera.cx = camera.cy = 32;
  RasterizeOptions options;
  options.compute_face_ids = true;
  const RasterResult r = Rasterize(sphere, camera, options);
  ASSERT_EQ(r.face_ids.size(), 64u * 64);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const int32_t f = r.face_ids[y * 64 + x];
      ASSERT_EQ(f >= 0, r.depth.at(x, y) > 0);
      if (f < 0) continue;
      // The pixel's 3D point lies on the plane of its face.
      const Eigen::Vector3d p = camera.PixelToCamera(x + 0.5, y + 0.5, r.depth.at(x, y));
      const auto& face = sphere.faces[f];
      const Eigen::Vector3d a = sphere.vertices[face[0]], b = sphere.vertices[face[1]],
                            c = sphere.vertices[face[2]];
      const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
      ASSERT_NEAR(n.dot(p - a), 0, 1e-6);
    }
  }
}

// No NaN or Inf leaves the rasteriser: huge and tiny coordinates, a vertex at the camera
// centre, a face seen exactly edge-on, a face entirely behind the camera.
TEST(RasterizerTest, ExtremeGeometryStaysFinite) {
  PinholeCamera camera = testing::CenteredCamera(48, 32, 40);
  TriangleMesh mesh;
  mesh.vertices = {{-1e30, -1e30, 1e30},
                   {1e30, -1e30, 1e30},
                   {0, 1e30, 1e30},  // huge
                   {0, 0, 0},
                   {1, 0, 1},
                   {0, 1, 1},  // at centre
                   {-1, 0, 2},
                   {1, 0, 2},
                   {0, 0, 5},  // edge-on
                   {-1, -1, -2},
                   {1, -1, -2},
                   {0, 1, -2},  // behind
                   {0, 0, 1e-30},
                   {1e-30, 0, 1e-30},
                   {0, 1e-30, 1e-30}};
  for (double z : {1e39, 1e300}) {  // beyond float range: no surface, never Inf
    mesh.vertices.push_back({-z, -z, z});
    mesh.vertices.push_back({z, -z, z});
    mesh.vertices.push_back({0, z, z});
  }
  for (int k = 0; k < 7; ++k) mesh.faces.push_back({3 * k, 3 * k + 1, 3 * k + 2});
  mesh.colors.assign(mesh.vertices.size(), Vector3ub(10, 20, 30));
  RasterizeOptions options;
  options.compute_color = true;
  for (double near : {1e-6, 1e-3}) {
    options.near_plane = near;
    const RasterResult r = Rasterize(mesh, camera, options);
    EXPECT_TRUE(AllFinite(r.depth));
    EXPECT_TRUE(AllFinite(r.color));
    int covered = 0;
    for (float d : r.depth.data) {
      EXPECT_TRUE(d == 0 || d >= near * 0.999) << d;
      covered += d > 0;
    }
    // The huge face fills the view, the one at the camera centre a corner.
    EXPECT_GT(covered, 0);
    EXPECT_TRUE(AllFinite(RayCastDepth(mesh, camera)));
    // Each face alone too (together the nearer huge face hides the farther ones).
    for (size_t k = 0; k < mesh.faces.size(); ++k) {
      TriangleMesh one = mesh;
      one.faces = {mesh.faces[k]};
      const RasterResult alone = Rasterize(one, camera, options);
      EXPECT_TRUE(AllFinite(alone.depth)) << k;
      EXPECT_TRUE(AllFinite(alone.color)) << k;
      EXPECT_TRUE(AllFinite(RayCastDepth(one, camera))) << k;
    }
  }
}

TEST(RasterizerTest, BadArgumentsThrow) {
  TriangleMesh mesh = MakeSphere(1);
  PinholeCamera camera;
  EXPECT_THROW(Rasterize(mesh, camera), Error);  // zero size
  camera.width = camera.height = 10;
  camera.fx = camera.fy = 10;
  EXPECT_NO_THROW(Rasterize(mesh, camera));
  RasterizeOptions options;
  options.compute_color = true;  // mesh has no colours
  EXPECT_THROW(Rasterize(mesh, camera, options), Error);
  options = RasterizeOptions();
  options.near_plane = 0;
  EXPECT_THROW(Rasterize(mesh, camera, options), Error);
  mesh.faces.push_back({0, 1, 1000});
  EXPECT_THROW(Rasterize(mesh, camera), Error);
  EXPECT_THROW(RayCastDepth(mesh, camera), Error);
  camera.fx = std::nan("");
  EXPECT_THROW(RayCastDepth(MakeSphere(1), camera), Error);
}

}  // namespace
}  // namespace fvs
