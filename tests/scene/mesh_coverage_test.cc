// Mesh coverage: the fraction of each view's pixels with a surface, the mean and the
// least covered view, on the in-memory test world and on hand-made depths.
#include "fvs/scene/mesh_coverage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scene/scene_fixture.h"

namespace fvs {
namespace {

TEST(MeshCoverageTest, SurfaceFractionCountsOnlyFinitePositiveDepths) {
  Image depth(4, 2, 1, 0.f);
  depth.at(0, 0) = 1.f;
  depth.at(1, 0) = 2.f;
  depth.at(2, 0) = std::numeric_limits<float>::infinity();
  depth.at(3, 0) = std::numeric_limits<float>::quiet_NaN();
  depth.at(0, 1) = -1.f;
  EXPECT_DOUBLE_EQ(SurfaceFraction(depth), 2.0 / 8.0);
  EXPECT_DOUBLE_EQ(SurfaceFraction(Image()), 0.0);
}

TEST(MeshCoverageTest, MeanAndLeastCoveredViewOfAScene) {
  const Scene scene = testing::MakeTestScene(4, 48, 36);
  const MeshCoverage coverage = MeasureMeshCoverage(scene);
  ASSERT_EQ(coverage.fractions.size(), 4u);
  double sum = 0;
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(coverage.names[i], scene.view(i).name);
    EXPECT_DOUBLE_EQ(coverage.fractions[i], SurfaceFraction(scene.SourceDepth(i)));
    EXPECT_GT(coverage.fractions[i], 0.0);
    EXPECT_LE(coverage.fractions[i], 1.0);
    EXPECT_LE(coverage.fractions[coverage.least], coverage.fractions[i]);
    sum += coverage.fractions[i];
  }
  EXPECT_NEAR(coverage.mean, sum / 4, 1e-12);
  EXPECT_NE(coverage.Summary().find(scene.view(coverage.least).name), std::string::npos);
  EXPECT_NE(coverage.ToJson().find("\"mean\""), std::string::npos);
  EXPECT_EQ(MeshCoverage().Summary(), "mesh coverage: no views");
}

}  // namespace
}  // namespace fvs
