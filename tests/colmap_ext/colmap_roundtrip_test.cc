// Round trips through the real COLMAP binary: models we write are read by
// `colmap model_converter` / `model_analyzer`, and what COLMAP writes we read back
// exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "colmap_ext/dense_io.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/model_fixture.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "support/test_support.h"

namespace fvs::colmap {
namespace {

using fvs::testing::ReadTextFile;
using fvs::testing::TempDir;

std::vector<std::string> SortedLines(const std::string& path) {
  std::istringstream in(ReadTextFile(path));
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  std::sort(lines.begin(), lines.end());
  return lines;
}

class ColmapRoundTrip : public ::testing::Test {
 protected:
  void SetUp() override {
    ::setenv("FVS_COLMAP_BIN", fvs::testing::RealColmapBinary().c_str(), 1);
    ::setenv("FVS_QUIET", "1", 1);
  }
  void Convert(const std::string& in, const std::string& out, const std::string& type) {
    CreateDirectories(out);  // model_converter aborts when the folder is missing
    RunColmap({"model_converter", "--input_path", in, "--output_path", out,
               "--output_type", type});
  }
  TempDir dir_;
};

TEST_F(ColmapRoundTrip, OurBinaryToColmapTextMatchesOurTextLineForLine) {
  const Reconstruction model = testing::MakeSampleModel();
  WriteSparseModelBinary(dir_ / "ours_bin", model);
  WriteSparseModelText(dir_ / "ours_txt", model);
  Convert(dir_ / "ours_bin", dir_ / "colmap_txt", "TXT");
  // COLMAP writes in hash-map order, so compare the sets of lines: same formatting, same
  // digits, same header.
  for (const char* f : {"cameras.txt", "images.txt", "points3D.txt"}) {
    EXPECT_EQ(SortedLines(dir_ / ("ours_txt/" + std::string(f))),
              SortedLines(dir_ / ("colmap_txt/" + std::string(f))))
        << f;
  }
  std::string why;
  EXPECT_TRUE(testing::ModelsEqual(model, ReadSparseModelText(dir_ / "colmap_txt"), &why))
      << why;
}

TEST_F(ColmapRoundTrip, OurTextToColmapBinaryReadsBackExactly) {
  const Reconstruction model = testing::MakeSampleModel();
  WriteSparseModelText(dir_ / "ours_txt", model);
  Convert(dir_ / "ours_txt", dir_ / "colmap_bin", "BIN");
  const Reconstruction back = ReadSparseModelBinary(dir_ / "colmap_bin");
  std::string why;
  EXPECT_TRUE(testing::ModelsEqual(model, back, &why)) << why;
  // And COLMAP's binary, rewritten by us, is what COLMAP turns into the same text.
  WriteSparseModelBinary(dir_ / "rewritten", back);
  Convert(dir_ / "rewritten", dir_ / "colmap_txt", "TXT");
  for (const char* f : {"cameras.txt", "images.txt", "points3D.txt"}) {
    WriteSparseModelText(dir_ / "ours_txt", back);
    EXPECT_EQ(SortedLines(dir_ / ("ours_txt/" + std::string(f))),
              SortedLines(dir_ / ("colmap_txt/" + std::string(f))));
  }
}

TEST_F(ColmapRoundTrip, ModelAnalyzerSeesWhatWeWrote) {
  const Reconstruction model = testing::MakeSampleModel();
  WriteSparseModelBinary(dir_ / "m", model);
  std::string output;
  RunColmapOptions options;
  options.on_line = [&](const std::string& line) { output += line + "\n"; };
  RunColmap({"model_analyzer", "--path", dir_ / "m"}, options);
  double error_sum = 0;
  for (const auto& [id, p] : model.points3D) error_sum += p.error;
  char expected_error[64];
  std::snprintf(expected_error, sizeof(expected_error), "Mean reprojection error: %.6fpx",
                error_sum / model.points3D.size());
  for (const std::string& expected :
       {std::string("Cameras: 11"), std::string("Images: 22"),
        std::string("Registered images: 22"), std::string("Points: 20"),
        std::string("Observations: 440"), std::string("Mean track length: 22.000000"),
        std::string(expected_error)}) {
    EXPECT_NE(output.find(expected), std::string::npos) << expected << "\n" << output;
  }
}

// Vertex count and positions of COLMAP's fused.ply (binary little endian: float x y z,
// float nx ny nz, uchar red green blue).
std::vector<Eigen::Vector3f> ReadFusedPly(const std::string& path) {
  const std::string data = ReadTextFile(path);
  const size_t header_end = data.find("end_header\n");
  const size_t count_at = data.find("element vertex ");
  if (header_end == std::string::npos || count_at == std::string::npos) return {};
  const size_t count = std::stoul(data.substr(count_at + 15));
  const size_t stride = 6 * 4 + 3;
  const char* body = data.data() + header_end + 11;
  std::vector<Eigen::Vector3f> points(count);
  if (data.size() - (header_end + 11) != count * stride) return {};
  for (size_t i = 0; i < count; ++i) std::memcpy(points[i].data(), body + i * stride, 12);
  return points;
}

TEST_F(ColmapRoundTrip, StereoFusionReadsOurDepthMapsAndWeReadItsVisibility) {
  // Three pinhole cameras side by side looking at the plane z = 5.
  const int w = 80, h = 60;
  Reconstruction model;
  Camera camera;
  camera.camera_id = 1;
  camera.model_id = kPinhole;
  camera.width = w;
  camera.height = h;
  camera.params = {60, 60, 40, 30};
  model.cameras[1] = camera;
  CreateDirectories(dir_ / "images");
  for (uint32_t i = 1; i <= 3; ++i) {
    Image image;
    image.image_id = i;
    image.camera_id = 1;
    image.name = "v" + std::to_string(i) + ".png";
    image.tvec = Eigen::Vector3d(-0.5 * (i - 2.0), 0, 0);
    model.images[i] = image;
    fvs::Image pixels(w, h, 3);
    for (size_t k = 0; k < pixels.data.size(); ++k)
      pixels.data[k] = (k * 37 % 101) / 100.0f;
    WriteImage(dir_ / ("images/" + image.name), pixels);
  }
  // Sparse points on the plane, seen by all three (fusion picks overlapping images by
  // them).
  for (uint64_t p = 1; p <= 12; ++p) {
    Point3D point;
    point.xyz = Eigen::Vector3d(-1.0 + 0.2 * p, 0.3 * ((p % 3) - 1.0), 5.0);
    for (auto& [id, image] : model.images) {
      Point2D observation;
      observation.xy = CameraWorldToImage(kPinhole, camera.params,
                                          (point.xyz + image.tvec).hnormalized());
      observation.point3D_id = p;
      point.track.push_back({id, static_cast<uint32_t>(image.points2D.size())});
      image.points2D.push_back(observation);
    }
    point.error = 0.1;
    model.points3D[p] = point;
  }
  WriteSparseModelBinary(dir_ / "sparse", model);
  RunColmap({"image_undistorter", "--image_path", dir_ / "images", "--input_path",
             dir_ / "sparse", "--output_path", dir_ / "ws"});
  const DenseWorkspace ws(dir_ / "ws");
  CheckDenseWorkspace(ws);
  for (const auto& [id, image] : model.images) {
    fvs::Image depth(w, h, 1, 5.0f);
    fvs::Image normals(w, h, 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) normals.at(x, y, 2) = -1.0f;
    CreateDirectories(ws.StereoDir() + "/depth_maps");
    CreateDirectories(ws.StereoDir() + "/normal_maps");
    WriteColmapArray(ws.DepthMapPath(image.name, "geometric"), depth);
    WriteColmapArray(ws.NormalMapPath(image.name, "geometric"), normals);
  }
  RunColmap(
      {"stereo_fusion", "--workspace_path", ws.root, "--input_type", "geometric",
       "--output_path", ws.FusedPath(), "--StereoFusion.num_threads", "2",
       // A point gets at most one pixel per view: 3 views cannot reach the default 5.
       "--StereoFusion.min_num_pixels", "2"});
  const std::vector<Eigen::Vector3f> fused = ReadFusedPly(ws.FusedPath());
  const std::vector<std::vector<uint32_t>> vis = ReadFusedVisibility(ws.FusedVisPath());
  ASSERT_GT(fused.size(), 100u);
  ASSERT_EQ(vis.size(), fused.size());
  size_t seen_by_all = 0;
  for (size_t i = 0; i < fused.size(); ++i) {
    EXPECT_NEAR(fused[i].z(), 5.0f, 1e-3) << i;  // COLMAP fused our depth of 5
    EXPECT_GE(vis[i].size(), 2u);
    for (const uint32_t image_idx : vis[i]) EXPECT_LT(image_idx, 3u);
    seen_by_all += vis[i].size() == 3;
  }
  EXPECT_GT(seen_by_all,
            fused.size() / 4);  // the middle of the plane is in all three views
}

}  // namespace
}  // namespace fvs::colmap
