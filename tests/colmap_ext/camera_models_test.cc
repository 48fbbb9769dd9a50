// Projection and unprojection of every COLMAP camera model: our own round trips, closed
// forms, and agreement with the real COLMAP (bundle_adjuster's initial reprojection cost
// for 2D points made by our projection; image_undistorter's undistorted camera, which
// COLMAP derives by unprojecting the image border).
#include "colmap_ext/camera_models.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>

#include "colmap_ext/image_io.h"
#include "colmap_ext/model_fixture.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/sparse_io.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs::colmap {
namespace {

using fvs::testing::TempDir;

TEST(CameraModels, NamesIdsAndParameterCounts) {
  const char* names[] = {"SIMPLE_PINHOLE",
                         "PINHOLE",
                         "SIMPLE_RADIAL",
                         "RADIAL",
                         "OPENCV",
                         "OPENCV_FISHEYE",
                         "FULL_OPENCV",
                         "FOV",
                         "SIMPLE_RADIAL_FISHEYE",
                         "RADIAL_FISHEYE",
                         "THIN_PRISM_FISHEYE"};
  const int counts[] = {3, 4, 4, 5, 8, 8, 12, 5, 4, 5, 12};
  for (int m = 0; m < kNumCameraModels; ++m) {
    EXPECT_EQ(CameraModelName(m), names[m]);
    EXPECT_EQ(CameraModelIdFromName(names[m]), m);
    EXPECT_EQ(CameraModelNumParams(m), counts[m]);
    const std::string info = CameraModelParamsInfo(m);
    EXPECT_EQ(std::count(info.begin(), info.end(), ',') + 1, counts[m]);
    EXPECT_EQ(CameraModelIsPinhole(m), m <= kPinhole);
  }
  EXPECT_EQ(CameraModelIdFromName("PINHOLE_X"), -1);
  EXPECT_EQ(CameraModelNumParams(11), -1);
  EXPECT_FALSE(IsKnownCameraModel(-1));
  EXPECT_THROW(CameraModelName(11), Error);
  EXPECT_THROW(CameraWorldToImage(kPinhole, {1, 2, 3}, {0, 0}), Error);
  EXPECT_THROW(CameraImageToWorld(99, {1, 2, 3}, {0, 0}), Error);
}

TEST(CameraModels, ClosedForms) {
  EXPECT_EQ(CameraWorldToImage(kSimplePinhole, {500, 320, 240}, {0.1, -0.2}),
            Eigen::Vector2d(370, 140));
  EXPECT_EQ(CameraImageToWorld(kPinhole, {500, 400, 320, 240}, {370, 140}),
            Eigen::Vector2d(0.1, -0.25));
  // SIMPLE_RADIAL: x = f * u * (1 + k r^2) + c.
  const Eigen::Vector2d p =
      CameraWorldToImage(kSimpleRadial, {500, 320, 240, 0.1}, {0.3, 0.4});
  EXPECT_NEAR(p.x(), 500 * 0.3 * 1.025 + 320, 1e-12);
  EXPECT_NEAR(p.y(), 500 * 0.4 * 1.025 + 240, 1e-12);
  // Equidistant fisheye without distortion: radius = f * atan(r).
  const Eigen::Vector2d q =
      CameraWorldToImage(kOpenCVFisheye, {300, 300, 0, 0, 0, 0, 0, 0}, {1.0, 0.0});
  EXPECT_NEAR(q.x(), 300 * M_PI / 4, 1e-12);
  EXPECT_NEAR(q.y(), 0, 1e-12);
  // FOV with omega: radius = atan(2 r tan(omega / 2)) / omega.
  const double omega = 0.9;
  const Eigen::Vector2d w = CameraWorldToImage(kFOV, {400, 400, 0, 0, omega}, {0.5, 0});
  EXPECT_NEAR(w.x(), 400 * std::atan(2 * 0.5 * std::tan(omega / 2)) / omega, 1e-12);
  // The principal point unprojects to the optical axis for every model.
  for (int m = 0; m < kNumCameraModels; ++m) {
    const std::vector<double> params = testing::SampleParams(m);
    const Eigen::Vector2d c = CameraWorldToImage(m, params, {0, 0});
    EXPECT_NEAR(CameraImageToWorld(m, params, c).norm(), 0, 1e-12) << CameraModelName(m);
  }
}

TEST(CameraModels, RoundTripsOverTheWholeImage) {
  for (int m = 0; m < kNumCameraModels; ++m) {
    const std::vector<double> params = testing::SampleParams(m);
    double worst_pixel = 0, worst_normalized = 0;
    for (double y = 0.5; y < 480; y += 23.5) {
      for (double x = 0.5; x < 640; x += 31.5) {
        const Eigen::Vector2d pixel(x, y);
        const Eigen::Vector2d n = CameraImageToWorld(m, params, pixel);
        ASSERT_TRUE(n.allFinite()) << CameraModelName(m);
        worst_pixel =
            std::max(worst_pixel, (CameraWorldToImage(m, params, n) - pixel).norm());
        const Eigen::Vector2d back =
            CameraImageToWorld(m, params, CameraWorldToImage(m, params, n));
        worst_normalized = std::max(worst_normalized, (back - n).norm());
      }
    }
    // COLMAP's Newton undistortion stops at a squared step of 1e-10 (in normalised
    // units); it converges quadratically, so the result is far better than that.
    EXPECT_LT(worst_pixel, 1e-6) << CameraModelName(m);
    EXPECT_LT(worst_normalized, 1e-9) << CameraModelName(m);
  }
}

TEST(CameraModels, FovSmallAngleBranchesAreConsistent) {
  // omega^2 < 1e-4 takes COLMAP's Taylor expansion; it must still invert.
  for (const double omega : {0.005, 0.9}) {
    const std::vector<double> params = {400, 400, 320, 240, omega};
    for (const Eigen::Vector2d& n :
         {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(0.004, 0.001)}) {
      const Eigen::Vector2d pixel = CameraWorldToImage(kFOV, params, n);
      EXPECT_NEAR((CameraImageToWorld(kFOV, params, pixel) - n).norm(), 0, 1e-6) << omega;
    }
  }
}

TEST(CameraModels, DistortionIsReallyApplied) {
  // Every distorted model moves a corner point by pixels, not by rounding error.
  for (int m = kSimpleRadial; m < kNumCameraModels; ++m) {
    const std::vector<double> params = testing::SampleParams(m);
    const bool single = m == kSimpleRadial || m == kRadial || m == kSimpleRadialFisheye ||
                        m == kRadialFisheye;
    const double f = params[0];
    const double cx = single ? params[1] : params[2];
    const Eigen::Vector2d n(0.7, 0.2);
    const double pinhole_x = f * n.x() + cx;
    EXPECT_GT(std::abs(CameraWorldToImage(m, params, n).x() - pinhole_x), 1.0)
        << CameraModelName(m);
  }
}

// COLMAP's bundle adjuster reports sqrt(cost / residuals) before it moves anything; with
// 2D points made by our projection the cost is what our projection disagrees with
// COLMAP's.
double ColmapInitialCost(const Reconstruction& model, const std::string& dir) {
  WriteSparseModelBinary(dir + "/in", model);
  CreateDirectories(dir + "/out");
  std::string output;
  RunColmapOptions options;
  options.on_line = [&](const std::string& line) { output += line + "\n"; };
  RunColmap({"bundle_adjuster", "--input_path", dir + "/in", "--output_path",
             dir + "/out", "--BundleAdjustment.max_num_iterations", "1",
             "--BundleAdjustment.refine_focal_length", "0",
             "--BundleAdjustment.refine_principal_point", "0",
             "--BundleAdjustment.refine_extra_params", "0"},
            options);
  std::smatch match;
  const std::regex initial(R"(Initial cost\s*:\s*([0-9.eE+-]+))");
  if (!std::regex_search(output, match, initial)) {
    ADD_FAILURE() << "no initial cost in\n" << output;
    return -1;
  }
  return std::stod(match[1]);
}

class CameraModelsVsColmap : public ::testing::Test {
 protected:
  void SetUp() override {
    ::setenv("FVS_COLMAP_BIN", fvs::testing::RealColmapBinary().c_str(), 1);
    ::setenv("FVS_QUIET", "1", 1);
  }
  TempDir dir_;
};

TEST_F(CameraModelsVsColmap, ProjectionAgreesWithColmapBundleAdjuster) {
  const Reconstruction all = testing::MakeSampleModel();
  for (int m = 0; m < kNumCameraModels; ++m) {
    // The model restricted to the images of camera m + 1.
    Reconstruction one = all;
    for (auto it = one.images.begin(); it != one.images.end();) {
      it = it->second.camera_id == static_cast<uint32_t>(m + 1) ? std::next(it)
                                                                : one.images.erase(it);
    }
    for (auto& [id, point] : one.points3D) {
      std::vector<TrackElement> kept;
      for (const TrackElement& el : point.track) {
        if (one.images.count(el.image_id)) kept.push_back(el);
      }
      point.track = kept;
    }
    const std::string sub = dir_ / CameraModelName(m);
    EXPECT_LT(ColmapInitialCost(one, sub + "/exact"), 1e-6) << CameraModelName(m);
    // Sensitivity: moving every observed 2D point by 0.5 px in x gives a cost of 0.25 px
    // (0.5 * 0.5^2 per observation over two residuals each).
    for (auto& [id, image] : one.images) {
      for (Point2D& p : image.points2D) p.xy.x() += 0.5;
    }
    EXPECT_NEAR(ColmapInitialCost(one, sub + "/shifted"), 0.25, 1e-4)
        << CameraModelName(m);
  }
}

// COLMAP 3.8's UndistortCamera (src/base/undistortion.cc) with default options
// (blank_pixels 0, min_scale 0.2, max_scale 2, no ROI, no size limit): the pinhole camera
// whose image holds no blank pixels, found by unprojecting the distorted image border.
Camera ExpectedUndistortedCamera(const Camera& camera) {
  const int m = camera.model_id;
  const auto& p = camera.params;
  if (CameraModelIsPinhole(m))
    return camera;  // COLMAP copies undistorted cameras as they are
  const bool single = m == kSimplePinhole || m == kSimpleRadial || m == kRadial ||
                      m == kSimpleRadialFisheye || m == kRadialFisheye;
  Camera out;
  out.model_id = kPinhole;
  out.width = camera.width;
  out.height = camera.height;
  out.params = single ? std::vector<double>{p[0], p[0], p[1], p[2]}
                      : std::vector<double>{p[0], p[1], p[2], p[3]};
  const double lowest = std::numeric_limits<double>::lowest();
  const double highest = std::numeric_limits<double>::max();
  double left_min_x = highest, left_max_x = lowest, right_min_x = highest,
         right_max_x = lowest;
  for (size_t y = 0; y < camera.height; ++y) {
    const Eigen::Vector2d l = CameraWorldToImage(
        kPinhole, out.params, CameraImageToWorld(m, p, Eigen::Vector2d(0.5, y + 0.5)));
    left_min_x = std::min(left_min_x, l.x());
    left_max_x = std::max(left_max_x, l.x());
    const Eigen::Vector2d r = CameraWorldToImage(
        kPinhole, out.params,
        CameraImageToWorld(m, p, Eigen::Vector2d(camera.width - 0.5, y + 0.5)));
    right_min_x = std::min(right_min_x, r.x());
    right_max_x = std::max(right_max_x, r.x());
  }
  double top_min_y = highest, top_max_y = lowest, bottom_min_y = highest,
         bottom_max_y = lowest;
  for (size_t x = 0; x < camera.width; ++x) {
    const Eigen::Vector2d t = CameraWorldToImage(
        kPinhole, out.params, CameraImageToWorld(m, p, Eigen::Vector2d(x + 0.5, 0.5)));
    top_min_y = std::min(top_min_y, t.y());
    top_max_y = std::max(top_max_y, t.y());
    const Eigen::Vector2d b = CameraWorldToImage(
        kPinhole, out.params,
        CameraImageToWorld(m, p, Eigen::Vector2d(x + 0.5, camera.height - 0.5)));
    bottom_min_y = std::min(bottom_min_y, b.y());
    bottom_max_y = std::max(bottom_max_y, b.y());
  }
  const double cx = out.params[2], cy = out.params[3];
  const double max_scale_x =
      std::max(cx / (cx - left_max_x), (out.width - 0.5 - cx) / (right_min_x - cx));
  const double max_scale_y =
      std::max(cy / (cy - top_max_y), (out.height - 0.5 - cy) / (bottom_min_y - cy));
  const double scale_x = std::clamp(1.0 / max_scale_x, 0.2, 2.0);
  const double scale_y = std::clamp(1.0 / max_scale_y, 0.2, 2.0);
  const uint64_t w0 = out.width, h0 = out.height;
  out.width = static_cast<uint64_t>(std::max(1.0, scale_x * w0));
  out.height = static_cast<uint64_t>(std::max(1.0, scale_y * h0));
  out.params[2] = cx * static_cast<double>(out.width) / static_cast<double>(w0);
  out.params[3] = cy * static_cast<double>(out.height) / static_cast<double>(h0);
  return out;
}

TEST_F(CameraModelsVsColmap, UnprojectionAgreesWithColmapImageUndistorter) {
  // One small image per camera model.
  Reconstruction model;
  const std::string images = dir_ / "images";
  CreateDirectories(images);
  for (int m = 0; m < kNumCameraModels; ++m) {
    Camera camera;
    camera.camera_id = m + 1;
    camera.model_id = m;
    camera.width = 160;
    camera.height = 120;
    camera.params = testing::SampleParams(m);
    // Scale the 640x480 sample intrinsics to 160x120 (focal lengths and principal point).
    const int num_scaled = m == kSimplePinhole || m == kSimpleRadial || m == kRadial ||
                                   m == kSimpleRadialFisheye || m == kRadialFisheye
                               ? 3
                               : 4;
    for (int k = 0; k < num_scaled; ++k) camera.params[k] /= 4;
    model.cameras[camera.camera_id] = camera;
    Image image;
    image.image_id = m + 1;
    image.camera_id = m + 1;
    image.name = "cam" + std::to_string(m) + ".png";
    model.images[image.image_id] = image;
    fvs::Image pixels(160, 120, 3, 0.5f);
    WriteImage(images + "/" + image.name, pixels);
  }
  WriteSparseModelBinary(dir_ / "sparse", model);
  RunColmap({"image_undistorter", "--image_path", images, "--input_path", dir_ / "sparse",
             "--output_path", dir_ / "dense", "--output_type", "COLMAP"});
  const Reconstruction undistorted = ReadSparseModel(dir_ / "dense/sparse");
  ASSERT_EQ(undistorted.images.size(), model.images.size());
  for (const auto& [id, image] : undistorted.images) {
    const Camera& got = undistorted.cameras.at(image.camera_id);
    const Camera& original =
        model.cameras.at(model.FindImageByName(image.name)->camera_id);
    const Camera expected = ExpectedUndistortedCamera(original);
    const std::string name = CameraModelName(original.model_id);
    EXPECT_EQ(got.model_id, expected.model_id) << name;
    EXPECT_EQ(got.width, expected.width) << name;
    EXPECT_EQ(got.height, expected.height) << name;
    ASSERT_EQ(got.params.size(), expected.params.size()) << name;
    for (size_t k = 0; k < got.params.size(); ++k) {
      EXPECT_NEAR(got.params[k], expected.params[k], 1e-9) << name;
    }
    if (!CameraModelIsPinhole(original.model_id)) {
      // Our distorted sample cameras all change the image size.
      EXPECT_TRUE(got.width != original.width || got.height != original.height) << name;
    }
  }
}

}  // namespace
}  // namespace fvs::colmap
