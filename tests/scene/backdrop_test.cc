// The backdrop fit (scene/backdrop.h): the icosphere, the culling that lets a camera
// inside see the surface around it and one outside only the far side, a room's walls
// found where the proxy mesh has only the object, a far sky left to infinity, and the
// degenerate cases (no mesh, too few photos, a scene 10 km out, black photos) with no
// non-finite vertex.
#include "fvs/scene/backdrop.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "fvs/util/error.h"
#include "scene/scene_fixture.h"

namespace fvs {
namespace {

using testing::ArcViews;
using testing::LookAtCamera;
using testing::RenderGroundTruth;

// The proxy of the test room's object alone: the box on the floor, no room.
TriangleMesh BoxOnlyMesh() {
  TriangleMesh mesh;
  const Eigen::Vector3d lo(-0.7, -0.5, 0), ex(1.4, 0, 0), ey(0, 1.0, 0), ez(0, 0, 1.2);
  testing::AddQuadGrid(&mesh, lo + ez, ex, ey, 6, 4, Eigen::Vector3d::Zero());
  testing::AddQuadGrid(&mesh, lo, ex, ez, 6, 5, Eigen::Vector3d::Zero());
  testing::AddQuadGrid(&mesh, lo + ey, ex, ez, 6, 5, Eigen::Vector3d::Zero());
  testing::AddQuadGrid(&mesh, lo, ey, ez, 4, 5, Eigen::Vector3d::Zero());
  testing::AddQuadGrid(&mesh, lo + ex, ey, ez, 4, 5, Eigen::Vector3d::Zero());
  return mesh;
}

std::vector<BackdropView> PhotosOf(const TriangleMesh& world, int n, int width,
                                   int height) {
  std::vector<BackdropView> views;
  for (const SceneView& v :
       ArcViews(n, width, height, Eigen::Vector3d::Zero(), -1.0, 2.0)) {
    views.push_back({v.camera, RenderGroundTruth(world, v.camera)});
  }
  return views;
}

void ExpectFiniteVertices(const TriangleMesh& mesh) {
  for (const Eigen::Vector3d& v : mesh.vertices) ASSERT_TRUE(v.allFinite());
}

TEST(BackdropTest, IcosphereHasTheRightCountsAndFacesOutward) {
  for (int s = 0; s <= 3; ++s) {
    const TriangleMesh m = Icosphere(s);
    const int scale = 1 << (2 * s);
    EXPECT_EQ(m.vertices.size(), static_cast<size_t>(10 * scale + 2));
    EXPECT_EQ(m.faces.size(), static_cast<size_t>(20 * scale));
    for (const Eigen::Vector3i& f : m.faces) {
      const Eigen::Vector3d a = m.vertices[f(0)], b = m.vertices[f(1)],
                            c = m.vertices[f(2)];
      ASSERT_GT((b - a).cross(c - a).dot(a + b + c), 0);  // counter-clockwise outside
    }
    for (const Eigen::Vector3d& v : m.vertices) EXPECT_NEAR(v.norm(), 1.0, 1e-12);
  }
}

// A sphere of radius 2 wound as FitBackdrop winds it (counter-clockwise from inside).
TriangleMesh InwardSphere() {
  TriangleMesh m = Icosphere(3);
  for (Eigen::Vector3d& v : m.vertices) v *= 2.0;
  for (Eigen::Vector3i& f : m.faces) std::swap(f(1), f(2));
  return m;
}

TEST(BackdropTest, ACameraInsideSeesTheSurfaceAroundItAndOneOutsideOnlyTheFarSide) {
  const TriangleMesh none;
  const TriangleMesh sphere = InwardSphere();
  const PinholeCamera inside =
      LookAtCamera(Eigen::Vector3d(0.3, 0, 0), Eigen::Vector3d(1, 1, 0), 64, 48);
  const Image depth_in = RenderWithBackdrop(none, sphere, inside);
  int seen = 0;
  for (float d : depth_in.data) seen += d > 0;
  EXPECT_EQ(seen, 64 * 48);

  const PinholeCamera outside =
      LookAtCamera(Eigen::Vector3d(6, 0, 0), Eigen::Vector3d::Zero(), 64, 48);
  const Image depth_out = RenderWithBackdrop(none, sphere, outside);
  int far = 0, near = 0;
  for (float d : depth_out.data) {
    // The far side lies beyond the tangent circle (depth 32 / 6 = 5.33), the near
    // side in front of it.
    if (d > 0) (d > 5.0 ? far : near) += 1;
  }
  EXPECT_GT(far, 100);
  EXPECT_EQ(near, 0);  // the near side faces away from the camera: culled

  // Where the mesh has a surface, the mesh's depth stands.
  TriangleMesh wall;
  testing::AddQuadGrid(&wall, {5, -5, -5}, {0, 10, 0}, {0, 0, 10}, 2, 2,
                       Eigen::Vector3d::Zero());
  const PinholeCamera facing =
      LookAtCamera(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0), 32, 24);
  for (float d : RenderWithBackdrop(wall, sphere, facing).data) {
    ASSERT_NEAR(d, 5.0, 1e-3);  // the wall, not the sphere at 2
  }
}

// The photos show the whole room; the proxy has only the box: the walls behind the box
// are found at about their distance, and a new camera sees them through the backdrop.
TEST(BackdropTest, FindsTheRoomsWallsWhereTheProxyHasOnlyTheObject) {
  const TriangleMesh world = testing::MakeTestWorldMesh();
  const TriangleMesh proxy = BoxOnlyMesh();
  const BackdropFit fit = FitBackdrop(PhotosOf(world, 16, 128, 96), proxy, {});
  ASSERT_FALSE(fit.mesh.faces.empty()) << fit.Summary();
  ExpectFiniteVertices(fit.mesh);
  EXPECT_GT(fit.num_finite, fit.num_infinity) << fit.Summary();

  const PinholeCamera novel = testing::ArcCamera(0.15, 128, 96);
  RasterizeOptions raster;
  const Image truth = Rasterize(world, novel, raster).depth;
  const Image object = Rasterize(proxy, novel, raster).depth;
  const Image depth = RenderWithBackdrop(proxy, fit.mesh, novel);
  std::vector<double> errors;
  int background = 0;
  for (size_t i = 0; i < depth.data.size(); ++i) {
    ASSERT_TRUE(std::isfinite(depth.data[i]));
    if (object.data[i] > 0) {
      ASSERT_EQ(depth.data[i], object.data[i]);
      continue;
    }
    ++background;
    if (depth.data[i] > 0) {
      errors.push_back(std::abs(depth.data[i] - truth.data[i]) / truth.data[i]);
    }
  }
  ASSERT_GT(background, 0);
  EXPECT_GT(errors.size(), 0.8 * background) << fit.Summary();
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.15) << fit.Summary();
}

// A textured sky 500 units out: no finite radius explains it as well as infinity, so the
// new camera's sky keeps no near backdrop.
TEST(BackdropTest, LeavesAFarSkyAtInfinity) {
  const TriangleMesh proxy = testing::MakeTestFloorAndBoxMesh();
  TriangleMesh world = proxy;
  const TriangleMesh sky = testing::MakeTestSkyMesh();
  const int base = static_cast<int>(world.vertices.size());
  world.vertices.insert(world.vertices.end(), sky.vertices.begin(), sky.vertices.end());
  world.colors.insert(world.colors.end(), sky.colors.begin(), sky.colors.end());
  for (const Eigen::Vector3i& f : sky.faces) {
    world.faces.push_back(f + Eigen::Vector3i::Constant(base));
  }
  const BackdropFit fit = FitBackdrop(PhotosOf(world, 16, 128, 96), proxy, {});
  ExpectFiniteVertices(fit.mesh);
  EXPECT_GT(fit.num_infinity, 0) << fit.Summary();

  const PinholeCamera novel = testing::ArcCamera(0.15, 128, 96);
  RasterizeOptions raster;
  const Image floor_and_box = Rasterize(proxy, novel, raster).depth;
  const Image depth = RenderWithBackdrop(proxy, fit.mesh, novel);
  int sky_pixels = 0, near_backdrop = 0;
  for (size_t i = 0; i < depth.data.size(); ++i) {
    if (floor_and_box.data[i] > 0) continue;
    ++sky_pixels;
    near_backdrop += depth.data[i] > 0;
  }
  ASSERT_GT(sky_pixels, 0);
  EXPECT_LT(near_backdrop, 0.2 * sky_pixels) << fit.Summary();
}

TEST(BackdropTest, DegenerateInputGivesAnEmptyOrFiniteBackdrop) {
  const TriangleMesh world = testing::MakeTestWorldMesh();
  const std::vector<BackdropView> photos = PhotosOf(world, 6, 64, 48);
  EXPECT_TRUE(FitBackdrop(photos, TriangleMesh(), {}).mesh.faces.empty());
  EXPECT_TRUE(FitBackdrop({photos[0], photos[1]}, BoxOnlyMesh(), {}).mesh.faces.empty());
  BackdropOptions off;
  off.enabled = false;
  EXPECT_TRUE(FitBackdrop(photos, BoxOnlyMesh(), off).mesh.faces.empty());
  EXPECT_EQ(off.ToString(), "backdrop=off");

  // A mesh of one point repeated: no radius.
  TriangleMesh point;
  point.vertices = {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1),
                    Eigen::Vector3d(1, 1, 1)};
  point.faces = {Eigen::Vector3i(0, 1, 2)};
  EXPECT_TRUE(FitBackdrop(photos, point, {}).mesh.faces.empty());

  // All-black photos: every radius agrees; whatever is kept is finite.
  std::vector<BackdropView> black = photos;
  for (BackdropView& v : black) std::fill(v.photo.data.begin(), v.photo.data.end(), 0.f);
  ExpectFiniteVertices(FitBackdrop(black, BoxOnlyMesh(), {}).mesh);

  // The same room 10 km from the origin.
  const Eigen::Vector3d offset(1e4, -1e4, 5e3);
  const TriangleMesh far_world = testing::MakeTestWorldMesh(offset);
  TriangleMesh far_box = BoxOnlyMesh();
  for (Eigen::Vector3d& v : far_box.vertices) v += offset;
  std::vector<BackdropView> far_photos;
  for (const SceneView& v : ArcViews(8, 64, 48, offset, -1.0, 2.0)) {
    far_photos.push_back({v.camera, RenderGroundTruth(far_world, v.camera)});
  }
  const BackdropFit far_fit = FitBackdrop(far_photos, far_box, {});
  ExpectFiniteVertices(far_fit.mesh);
  EXPECT_LT((far_fit.centre - offset).norm(), 2.0);
}

TEST(BackdropTest, InvalidOptionsAreRejectedWithTheirName) {
  auto expect_error = [](auto change, const char* name) {
    BackdropOptions o;
    change(o);
    try {
      o.Check();
      ADD_FAILURE() << name << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  expect_error([](BackdropOptions& o) { o.subdivisions = 9; }, "subdivisions");
  expect_error([](BackdropOptions& o) { o.max_image_size = 4; }, "max_image_size");
  expect_error([](BackdropOptions& o) { o.num_radii = 1; }, "num_radii");
  expect_error([](BackdropOptions& o) { o.min_radius = NAN; }, "min_radius");
  expect_error([](BackdropOptions& o) { o.max_radius = -1; }, "max_radius");
  expect_error([](BackdropOptions& o) { o.min_views = 1; }, "min_views");
  expect_error([](BackdropOptions& o) { o.infinity_margin = INFINITY; },
               "infinity_margin");
  expect_error([](BackdropOptions& o) { o.max_colour_std = 0; }, "max_colour_std");
  expect_error([](BackdropOptions& o) { o.smoothing_iterations = -1; },
               "smoothing_iterations");
}

}  // namespace
}  // namespace fvs
