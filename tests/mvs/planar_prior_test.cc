// Planar priors (planar_prior.h) on the analytic scene, whose exact depth is known: holes
// cut into a true depth map are filled with the right depth, wrong planes are vetoed by
// the sources, and degenerate input (no supports, black images, points at 10 km) fills
// nothing and never writes a non-finite value.
#include "fvs/mvs/planar_prior.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "fvs/mvs/stereo_test_scene.h"
#include "fvs/util/error.h"

namespace fvs::mvs {
namespace {

struct Fixture {
  AnalyticScene scene;
  std::vector<StereoView> views;
  std::vector<int> sources;
  std::vector<const Image*> source_depths;
};

Fixture MakeFixture(int num_views = 5) {
  AnalyticSceneOptions options;
  options.num_views = num_views;
  options.width = 160;
  options.height = 120;
  options.num_sparse_points = 1500;
  Fixture f;
  f.scene = RenderAnalyticScene(options);
  for (size_t v = 0; v < f.scene.cameras.size(); ++v) {
    StereoView view;
    view.name = f.scene.names[v];
    view.camera = f.scene.cameras[v];
    view.grey = Image(view.camera.width, view.camera.height, 1);
    for (size_t i = 0; i < view.grey.data.size(); ++i) {
      view.grey.data[i] = f.scene.images[v].data[3 * i];
    }
    view.depth_min = 0.5;
    view.depth_max = 100;
    f.views.push_back(view);
  }
  for (int v = 1; v < num_views; ++v) {
    f.sources.push_back(v);
    f.source_depths.push_back(&f.scene.depths[v]);
  }
  return f;
}

// The reference's true map (normals left zero: the filler reads only depth and cost)
// with the pixels of `hole` removed.
DepthNormalMap TrueMapWithHole(const Fixture& f, int x0, int y0, int x1, int y1) {
  DepthNormalMap map;
  map.depth = f.scene.depths[0];
  map.normal = Image(map.depth.width, map.depth.height, 3);
  map.cost = Image(map.depth.width, map.depth.height, 1, 0.1f);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      map.depth.at(x, y) = 0;
      map.cost.at(x, y) = 2;
    }
  }
  return map;
}

struct HoleScore {
  int hole = 0, filled = 0, within_1 = 0;
};

HoleScore Score(const DepthNormalMap& map, const Image& truth, int x0, int y0, int x1,
                int y1) {
  HoleScore s;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      ++s.hole;
      const float d = map.depth.at(x, y);
      EXPECT_TRUE(std::isfinite(d));
      if (!(d > 0)) continue;
      ++s.filled;
      const Eigen::Vector3d n(map.normal.at(x, y, 0), map.normal.at(x, y, 1),
                              map.normal.at(x, y, 2));
      EXPECT_NEAR(n.norm(), 1.0, 1e-4);
      if (std::abs(d - truth.at(x, y)) <= 0.01 * truth.at(x, y)) ++s.within_1;
    }
  }
  std::printf("hole %d px, filled %d, within 1%%: %d\n", s.hole, s.filled, s.within_1);
  return s;
}

TEST(PlanarPriorTest, FillsAHoleWithTheTrueDepth) {
  const Fixture f = MakeFixture();
  // On the back wall: one plane, mostly filled.
  {
    const int x0 = 30, y0 = 6, x1 = 130, y1 = 40;
    DepthNormalMap map = TrueMapWithHole(f, x0, y0, x1, y1);
    const PlanarPriorStats stats =
        FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, {}, nullptr},
                             PlanarPriorOptions(), &map);
    EXPECT_GE(stats.empty, (x1 - x0) * (y1 - y0));  // and where the scene has no surface
    const HoleScore s = Score(map, f.scene.depths[0], x0, y0, x1, y1);
    EXPECT_EQ(s.filled, stats.filled);
    EXPECT_GE(s.filled, 0.6 * s.hole);  // 72 %: conservative near the box and the border
    EXPECT_GE(s.within_1, 0.95 * s.filled);
    EXPECT_EQ(map.depth.at(5, 5), f.scene.depths[0].at(5, 5));  // outside: untouched
  }
  // Across the box, the wall and the edges between them: no support group there is
  // coplanar, so little is filled, but what is filled is right.
  {
    const int x0 = 40, y0 = 30, x1 = 120, y1 = 90;
    DepthNormalMap map = TrueMapWithHole(f, x0, y0, x1, y1);
    FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, {}, nullptr},
                         PlanarPriorOptions(), &map);
    const HoleScore s = Score(map, f.scene.depths[0], x0, y0, x1, y1);
    EXPECT_GT(s.filled, 0);
    EXPECT_GE(s.within_1, 0.95 * s.filled);
  }
}

TEST(PlanarPriorTest, SfmPointsAloneSupportAPlane) {
  Fixture f = MakeFixture();
  // No confident pixel at all: only the sparse points the scene's tracks give.
  DepthNormalMap map = TrueMapWithHole(f, 0, 0, 160, 120);
  std::vector<Eigen::Vector3d> points;
  for (const AnalyticScene::Track& t : f.scene.tracks) {
    for (const auto& [view, uv] : t.observations) {
      if (view == 0) points.push_back(t.xyz);
    }
  }
  ASSERT_GT(points.size(), 100u);
  PlanarPriorOptions options;
  const PlanarPriorStats stats = FillFromPlanarPriors(
      f.views, {0, f.sources, f.source_depths, points, nullptr}, options, &map);
  const HoleScore s = Score(map, f.scene.depths[0], 0, 0, 160, 120);
  EXPECT_GT(stats.filled, 0);
  EXPECT_GE(s.filled, s.hole / 3);
  EXPECT_GE(s.within_1, 0.9 * s.filled);
}

TEST(PlanarPriorTest, SourcesVetoAPlaneInFrontOfWhatTheySee) {
  const Fixture f = MakeFixture();
  const int x0 = 40, y0 = 30, x1 = 120, y1 = 90;
  DepthNormalMap map = TrueMapWithHole(f, x0, y0, x1, y1);
  // Supports pulled 20 % towards the camera: every source saw the surface behind them.
  for (float& d : map.depth.data) d *= 0.8f;
  const PlanarPriorStats stats = FillFromPlanarPriors(
      f.views, {0, f.sources, f.source_depths, {}, nullptr}, PlanarPriorOptions(), &map);
  EXPECT_GT(stats.candidates, 0);
  EXPECT_EQ(stats.filled, 0);
}

TEST(PlanarPriorTest, KeepsAPhotometricDepthOneSourceConfirms) {
  Fixture f = MakeFixture();
  const int x0 = 30, y0 = 6, x1 = 130, y1 = 40;
  // One source measured the wall; the others have no depth and show nothing alike.
  const Image none(160, 120, 1);
  for (size_t s = 1; s < f.sources.size(); ++s) {
    f.source_depths[s] = &none;
    StereoView& v = f.views[f.sources[s]];
    std::fill(v.grey.data.begin(), v.grey.data.end(), 1.f);
  }
  DepthNormalMap without = TrueMapWithHole(f, x0, y0, x1, y1);
  EXPECT_EQ(FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, {}, nullptr},
                                 PlanarPriorOptions(), &without)
                .filled,
            0);
  // The reference's photometric depth there (the truth, as the filter removed it).
  DepthNormalMap with = TrueMapWithHole(f, x0, y0, x1, y1);
  const PlanarPriorStats stats = FillFromPlanarPriors(
      f.views, {0, f.sources, f.source_depths, {}, &f.scene.depths[0]},
      PlanarPriorOptions(), &with);
  const HoleScore s = Score(with, f.scene.depths[0], x0, y0, x1, y1);
  EXPECT_GT(stats.filled, 0);
  EXPECT_EQ(s.within_1, s.filled);
}

TEST(PlanarPriorTest, DegenerateInputFillsNothingAndStaysFinite) {
  Fixture f = MakeFixture(3);
  PlanarPriorOptions options;
  // No supports at all.
  DepthNormalMap empty = TrueMapWithHole(f, 0, 0, 160, 120);
  EXPECT_EQ(FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, {}, nullptr},
                                 options, &empty)
                .filled,
            0);
  // SfM points at 10 km (outside the depth range) and one collinear row of supports.
  DepthNormalMap row = TrueMapWithHole(f, 0, 0, 160, 120);
  for (int x = 0; x < 160; ++x) row.depth.at(x, 60) = f.scene.depths[0].at(x, 60);
  const std::vector<Eigen::Vector3d> far = {{1e4, 0, 1e4}, {0, 1e4, 1e4}, {-1e4, 0, 1e4}};
  FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, far, nullptr}, options,
                       &row);
  for (float d : row.depth.data) EXPECT_TRUE(std::isfinite(d));
  for (float n : row.normal.data) EXPECT_TRUE(std::isfinite(n));
  // All-black photos and sources without depth: the grey test passes everywhere, yet
  // nothing non-finite is written and the supports' plane is the only one used.
  for (StereoView& v : f.views) std::fill(v.grey.data.begin(), v.grey.data.end(), 0.f);
  const Image none(160, 120, 1);
  const std::vector<const Image*> no_depths(f.sources.size(), &none);
  DepthNormalMap black = TrueMapWithHole(f, 40, 30, 120, 90);
  FillFromPlanarPriors(f.views, {0, f.sources, no_depths, far, nullptr}, options, &black);
  for (float d : black.depth.data) EXPECT_TRUE(std::isfinite(d));
  for (float n : black.normal.data) EXPECT_TRUE(std::isfinite(n));
}

TEST(PlanarPriorTest, BadOptionsAndSizesThrow) {
  const Fixture f = MakeFixture(3);
  DepthNormalMap map = TrueMapWithHole(f, 0, 0, 10, 10);
  PlanarPriorOptions bad;
  bad.cell_size = 1;
  EXPECT_THROW(bad.Check(), Error);
  bad = PlanarPriorOptions();
  bad.depth_tolerance = 0;
  EXPECT_THROW(FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, {}, nullptr},
                                    bad, &map),
               Error);
  const std::vector<const Image*> one(1, f.source_depths[0]);
  EXPECT_THROW(FillFromPlanarPriors(f.views, {0, f.sources, one, {}, nullptr},
                                    PlanarPriorOptions(), &map),
               Error);
  PlanarPriorOptions off;
  off.enabled = false;
  EXPECT_EQ(off.ToString(), "planar_prior=0");
  EXPECT_EQ(FillFromPlanarPriors(f.views, {0, f.sources, f.source_depths, {}, nullptr},
                                 off, &map)
                .filled,
            0);
}

}  // namespace
}  // namespace fvs::mvs
