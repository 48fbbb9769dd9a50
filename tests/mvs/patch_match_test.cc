// PatchMatch on in-memory views of the analytic scene (stereo_test_scene.h): exact depth
// is known, so accuracy is checked against it, not against a previous run.
#include "fvs/mvs/patch_match.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "fvs/mvs/patch_match_stereo.h"
#include "fvs/mvs/stereo_test_scene.h"
#include "fvs/util/error.h"

namespace fvs::mvs {
namespace {

std::vector<StereoView> ViewsOf(const AnalyticScene& scene) {
  std::vector<StereoView> views;
  for (size_t v = 0; v < scene.cameras.size(); ++v) {
    StereoView view;
    view.name = scene.names[v];
    view.camera = scene.cameras[v];
    view.grey = Image(view.camera.width, view.camera.height, 1);
    for (size_t i = 0; i < view.grey.data.size(); ++i) {
      view.grey.data[i] = scene.images[v].data[3 * i];
    }
    double lo = 1e30, hi = 0;
    for (float d : scene.depths[v].data) {
      if (d > 0) {
        lo = std::min<double>(lo, d);
        hi = std::max<double>(hi, d);
      }
    }
    view.depth_min = 0.8 * lo;
    view.depth_max = 1.2 * hi;
    views.push_back(view);
  }
  return views;
}

std::vector<int> AllBut(int ref, int n) {
  std::vector<int> sources;
  for (int v = 0; v < n; ++v) {
    if (v != ref) sources.push_back(v);
  }
  return sources;
}

struct Accuracy {
  int num_pixels = 0;   // with ground truth, away from the border
  double within_1 = 0;  // fraction within 1% relative depth error
  double without_depth = 0;
  double kept_within_1 = 0;  // among pixels with a depth
};

// Relative-error histogram over pixels with ground truth (the border, where the NCC
// window is clamped, excluded); printed so that a change in quality is visible in the
// test log.
Accuracy Evaluate(const DepthNormalMap& map, const Image& gt, int border,
                  const char* label) {
  static const double kEdges[] = {0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1};
  int hist[8] = {0};
  Accuracy acc;
  int zero = 0, good = 0;
  for (int y = border; y < gt.height - border; ++y) {
    for (int x = border; x < gt.width - border; ++x) {
      const double g = gt.at(x, y);
      if (g <= 0) continue;
      ++acc.num_pixels;
      const double d = map.depth.at(x, y);
      if (d <= 0) {
        ++zero;
        continue;
      }
      const double e = std::abs(d - g) / g;
      int b = 0;
      while (b < 7 && e > kEdges[b]) ++b;
      ++hist[b];
      if (e <= 0.01) ++good;
    }
  }
  acc.within_1 = static_cast<double>(good) / acc.num_pixels;
  acc.without_depth = static_cast<double>(zero) / acc.num_pixels;
  acc.kept_within_1 = static_cast<double>(good) / std::max(1, acc.num_pixels - zero);
  std::printf("%s: %d px, within 1%%: %.3f, no depth: %.3f, histogram of |d-gt|/gt:\n",
              label, acc.num_pixels, acc.within_1, acc.without_depth);
  const char* names[] = {"<=0.1%", "<=0.2%", "<=0.5%", "<=1%",
                         "<=2%",   "<=5%",   "<=10%",  ">10%"};
  for (int b = 0; b < 8; ++b) {
    std::printf("  %-7s %.3f\n", names[b], static_cast<double>(hist[b]) / acc.num_pixels);
  }
  return acc;
}

TEST(PatchMatchTest, PlaneHomographyMapsPointsOfThePlane) {
  AnalyticSceneOptions options;
  options.num_views = 2;
  options.width = 64;
  options.height = 48;
  options.num_sparse_points = 0;
  const AnalyticScene scene = RenderAnalyticScene(options);
  const PinholeCamera& ref = scene.cameras[0];
  const PinholeCamera& src = scene.cameras[1];
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, -1.0).normalized();
  const double u = 20.5, v = 30.5, depth = 4.0;
  const Eigen::Matrix3d H = PlaneHomography(ref, src, n, u, v, depth);
  const Eigen::Vector3d x0 = ref.PixelToCamera(u, v, depth);
  // Another point of the same plane, seen at pixel (u2, v2) of the reference.
  const double u2 = 40.25, v2 = 10.75;
  const Eigen::Vector3d ray = ref.PixelToCamera(u2, v2, 1.0);
  const Eigen::Vector3d x1 = ray * (n.dot(x0) / n.dot(ray));
  const Eigen::Vector2d expected =
      src.CameraToPixel(src.WorldToCamera(ref.CameraToWorld(x1)));
  const Eigen::Vector3d h = H * Eigen::Vector3d(u2, v2, 1.0);
  EXPECT_NEAR(h.x() / h.z(), expected.x(), 1e-9);
  EXPECT_NEAR(h.y() / h.z(), expected.y(), 1e-9);
}

// The pipeline's two passes: photometric maps of every view (unfiltered), then the
// geometric pass of `ref` against them, filtered. `ref_photometric`, when given,
// receives ref's photometric map.
DepthNormalMap PhotometricThenGeometric(const std::vector<StereoView>& views, int ref,
                                        PatchMatchOptions pm,
                                        DepthNormalMap* ref_photometric = nullptr) {
  const int n = static_cast<int>(views.size());
  pm.filter = false;
  std::vector<DepthNormalMap> photometric(n);
  for (int v = 0; v < n; ++v) photometric[v] = PatchMatchView(views, v, AllBut(v, n), pm);
  std::vector<const Image*> source_depths;
  for (int s : AllBut(ref, n)) source_depths.push_back(&photometric[s].depth);
  pm.filter = true;
  if (ref_photometric) *ref_photometric = photometric[ref];
  return PatchMatchView(views, ref, AllBut(ref, n), pm, &source_depths,
                        &photometric[ref]);
}

TEST(PatchMatchTest, PhotometricThenGeometricRecoverExactDepth) {
  AnalyticSceneOptions options;
  options.num_views = 6;
  options.width = 160;
  options.height = 120;
  options.num_sparse_points = 0;
  const AnalyticScene scene = RenderAnalyticScene(options);
  const std::vector<StereoView> views = ViewsOf(scene);
  const PatchMatchOptions pm;
  const int ref = 2;
  const int border = pm.window_radius;
  // Photometric maps feed the geometric pass unfiltered, as COLMAP's.
  DepthNormalMap photometric_ref;
  const DepthNormalMap geometric =
      PhotometricThenGeometric(views, ref, pm, &photometric_ref);
  const Accuracy photo =
      Evaluate(photometric_ref, scene.depths[ref], border, "photometric");
  EXPECT_GE(photo.within_1, 0.85);
  EXPECT_EQ(photo.without_depth, 0.0);  // every pixel of this scene is textured

  const Accuracy geo = Evaluate(geometric, scene.depths[ref], border, "geometric+filter");
  EXPECT_GE(geo.within_1, 0.85);
  // Filtering removes mostly wrong pixels: what is kept is more accurate.
  EXPECT_GT(geo.kept_within_1, photo.within_1);
  EXPECT_GE(geo.kept_within_1, 0.88);
  EXPECT_LT(geo.without_depth, 0.15);

  // Normals: unit, facing the camera, close to the truth on the fronto-parallel box face.
  const PinholeCamera& cam = scene.cameras[ref];
  int checked = 0;
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const float d = geometric.depth.at(x, y);
      ASSERT_TRUE(std::isfinite(d));
      const Eigen::Vector3d nrm(geometric.normal.at(x, y, 0),
                                geometric.normal.at(x, y, 1),
                                geometric.normal.at(x, y, 2));
      ASSERT_TRUE(nrm.allFinite());
      if (d <= 0) {
        EXPECT_EQ(nrm.norm(), 0.0);
        continue;
      }
      EXPECT_NEAR(nrm.norm(), 1.0, 1e-4);
      EXPECT_LT(nrm.dot(cam.PixelToCamera(x + 0.5, y + 0.5, 1.0)), 0.0);
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
  // The box front face (world normal -z) at the image centre of the middle view.
  const int cx = cam.width / 2, cy = cam.height / 2;
  const Eigen::Vector3d world_normal(0, 0, -1);
  const Eigen::Vector3d expected = cam.R * world_normal;
  Eigen::Vector3d mean_normal = Eigen::Vector3d::Zero();
  for (int y = cy - 3; y <= cy + 3; ++y) {
    for (int x = cx - 3; x <= cx + 3; ++x) {
      mean_normal +=
          Eigen::Vector3d(geometric.normal.at(x, y, 0), geometric.normal.at(x, y, 1),
                          geometric.normal.at(x, y, 2));
    }
  }
  ASSERT_GT(mean_normal.norm(), 0.0);
  EXPECT_GT(mean_normal.normalized().dot(expected), std::cos(10.0 * M_PI / 180.0));
}

TEST(PatchMatchTest, ResultDoesNotDependOnThreadCount) {
  AnalyticSceneOptions options;
  options.num_views = 3;
  options.width = 64;
  options.height = 48;
  options.num_sparse_points = 0;
  const AnalyticScene scene = RenderAnalyticScene(options);
  const std::vector<StereoView> views = ViewsOf(scene);
  PatchMatchOptions pm;
  pm.num_iterations = 2;
  pm.num_threads = 1;
  const DepthNormalMap one = PatchMatchView(views, 1, {0, 2}, pm);
  pm.num_threads = 2;
  const DepthNormalMap two = PatchMatchView(views, 1, {0, 2}, pm);
  EXPECT_EQ(one.depth.data, two.depth.data);
  EXPECT_EQ(one.normal.data, two.normal.data);
}

TEST(PatchMatchTest, BadInputThrowsError) {
  AnalyticSceneOptions options;
  options.num_views = 2;
  options.width = 32;
  options.height = 24;
  options.num_sparse_points = 0;
  const AnalyticScene scene = RenderAnalyticScene(options);
  std::vector<StereoView> views = ViewsOf(scene);
  const PatchMatchOptions pm;
  EXPECT_THROW(PatchMatchView(views, 0, {}, pm), Error);
  EXPECT_THROW(PatchMatchView(views, 0, {0}, pm), Error);
  EXPECT_THROW(PatchMatchView(views, 0, {5}, pm), Error);
  EXPECT_THROW(PatchMatchView(views, 3, {1}, pm), Error);
  std::vector<StereoView> bad_range = views;
  bad_range[0].depth_min = 0;
  EXPECT_THROW(PatchMatchView(bad_range, 0, {1}, pm), Error);
  std::vector<StereoView> bad_size = views;
  bad_size[1].grey = Image(10, 10, 1);
  EXPECT_THROW(PatchMatchView(bad_size, 0, {1}, pm), Error);
  std::vector<const Image*> wrong_count;
  EXPECT_THROW(PatchMatchView(views, 0, {1}, pm, &wrong_count), Error);
  PatchMatchOptions bad = pm;
  bad.window_radius = 0;
  EXPECT_THROW(PatchMatchView(views, 0, {1}, bad), Error);
  bad = pm;
  bad.depth_perturbation = std::nan("");
  EXPECT_THROW(bad.Check(), Error);
  bad = pm;
  bad.sigma_color = std::numeric_limits<double>::infinity();
  EXPECT_THROW(bad.Check(), Error);
  bad = pm;
  bad.sigma_spatial = std::nan("");
  EXPECT_THROW(bad.Check(), Error);
}

TEST(PatchMatchTest, TexturelessPixelsGetNoDepth) {
  AnalyticSceneOptions options;
  options.num_views = 2;
  options.width = 48;
  options.height = 36;
  options.num_sparse_points = 0;
  const AnalyticScene scene = RenderAnalyticScene(options);
  std::vector<StereoView> views = ViewsOf(scene);
  for (StereoView& v : views) std::fill(v.grey.data.begin(), v.grey.data.end(), 0.5f);
  PatchMatchOptions pm;
  pm.num_iterations = 1;
  pm.filter = false;
  const DepthNormalMap map = PatchMatchView(views, 0, {1}, pm);
  for (float d : map.depth.data) EXPECT_EQ(d, 0.f);
  for (float n : map.normal.data) EXPECT_EQ(n, 0.f);
}

// Plain tiles with textured grout: the 7x7 window of a tile's centre sees no texture,
// the same window spread 8x reaches the grout. Spread windows fill the tiles about as
// accurately as the grout is measured, and leave the grout's pixels their depth.
TEST(PatchMatchTest, WideWindowsFillPlainTiles) {
  AnalyticSceneOptions options;
  options.num_views = 5;
  options.width = 240;
  options.height = 180;
  options.num_sparse_points = 0;
  options.tile_size = 0.6;
  const AnalyticScene scene = RenderAnalyticScene(options);
  const std::vector<StereoView> views = ViewsOf(scene);
  const int ref = 2;
  PatchMatchOptions pm;
  pm.max_window_scale = 1;
  const DepthNormalMap plain = PhotometricThenGeometric(views, ref, pm);
  pm.max_window_scale = 8;
  const DepthNormalMap wide = PhotometricThenGeometric(views, ref, pm);
  const int border = 3;
  const Image& gt = scene.depths[ref];
  const Accuracy a = Evaluate(plain, gt, border, "window scale 1");
  const Accuracy b = Evaluate(wide, gt, border, "window scale 8");
  EXPECT_LT(b.without_depth, 0.5 * a.without_depth);
  EXPECT_GT(b.within_1, a.within_1 + 0.1);
  // Of the pixels only the spread windows give depth, most are right.
  int added = 0, added_good = 0, lost = 0;
  for (int y = border; y < gt.height - border; ++y) {
    for (int x = border; x < gt.width - border; ++x) {
      const double g = gt.at(x, y), d = wide.depth.at(x, y);
      ASSERT_TRUE(std::isfinite(d));
      if (g <= 0) continue;
      if (plain.depth.at(x, y) > 0) {
        lost += d <= 0;
        continue;
      }
      if (d <= 0) continue;
      ++added;
      added_good += std::abs(d - g) <= 0.01 * g;
    }
  }
  std::printf("added %d px, %.3f within 1%%; lost %d\n", added,
              static_cast<double>(added_good) / std::max(added, 1), lost);
  EXPECT_GT(added, 0);
  EXPECT_GE(added_good, 0.7 * added);  // 0.76 measured; the grout's own kept pixels 0.85
  EXPECT_LT(lost, 0.05 * added);
  PatchMatchOptions bad;
  bad.max_window_scale = 3;
  EXPECT_THROW(bad.Check(), Error);
}

TEST(PatchMatchTest, DownscaleGreyAveragesAreas) {
  Image grey(7, 5, 1);
  double sum = 0;
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 7; ++x) {
      grey.at(x, y) = static_cast<float>((x * 3 + y * 5) % 11) / 10.f;
      sum += grey.at(x, y);
    }
  }
  const Image small = DownscaleGrey(grey, 3, 2);
  ASSERT_EQ(small.width, 3);
  ASSERT_EQ(small.height, 2);
  double small_sum = 0;
  for (float v : small.data) small_sum += v;
  // Equal-area cells: the mean is preserved.
  EXPECT_NEAR(small_sum / 6.0, sum / 35.0, 1e-5);
  Image constant(9, 9, 1, 0.25f);
  for (float v : DownscaleGrey(constant, 4, 4).data) EXPECT_NEAR(v, 0.25f, 1e-6);
  EXPECT_THROW(DownscaleGrey(constant, 10, 4), Error);
}

}  // namespace
}  // namespace fvs::mvs
