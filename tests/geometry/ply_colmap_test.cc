// PLY interoperability with the real COLMAP binary: what COLMAP writes, we read. Skipped
// when no COLMAP is installed. (COLMAP reading ours would go through poisson_mesher,
// which takes minutes and, on Debian's build, wrote an empty mesh: not a unit test.)
#include <gtest/gtest.h>

#include "fvs/geometry/ply.h"
#include "support/test_support.h"

namespace fvs {
namespace {

using testing::RealColmapBinary;
using testing::RunShell;
using testing::TempDir;
using testing::WriteTextFile;

bool HaveColmap() { return RunShell(RealColmapBinary() + " help > /dev/null 2>&1") == 0; }

TEST(PlyColmapTest, ReadsThePointCloudColmapWrites) {
  if (!HaveColmap()) GTEST_SKIP() << "no COLMAP binary";
  TempDir dir;
  RunShell("mkdir -p " + dir / "sparse");
  WriteTextFile(dir / "sparse/cameras.txt", "1 PINHOLE 100 100 50 50 50 50\n");
  WriteTextFile(dir / "sparse/images.txt", "1 1 0 0 0 0 0 0 1 a.jpg\n\n");
  WriteTextFile(dir / "sparse/points3D.txt",
                "1 1.5 -2.25 3.125 255 0 10 0.5\n7 100000.5 0.001 -7 1 2 3 0.1\n");
  std::string log;
  ASSERT_EQ(
      RunShell("QT_QPA_PLATFORM=offscreen " + RealColmapBinary() +
                   " model_converter --input_path " + dir / "sparse" + " --output_path " +
                   dir / "points.ply" + " --output_type PLY 2>&1",
               &log),
      0)
      << log;
  const PointCloud cloud = ReadPlyPointCloud(dir / "points.ply");
  ASSERT_EQ(cloud.size(), 2u);
  ASSERT_EQ(cloud.colors.size(), 2u);
  // COLMAP may write the points in any order.
  const int a = cloud.points[0].x() < 10 ? 0 : 1;
  EXPECT_EQ(cloud.points[a], Eigen::Vector3d(1.5, -2.25, 3.125));
  EXPECT_EQ(cloud.colors[a], Vector3ub(255, 0, 10));
  EXPECT_EQ(cloud.points[1 - a],
            Eigen::Vector3d(100000.5, static_cast<float>(0.001), -7));  // float file
  EXPECT_EQ(cloud.colors[1 - a], Vector3ub(1, 2, 3));
}

}  // namespace
}  // namespace fvs
