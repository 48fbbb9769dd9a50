// End to end: real COLMAP SfM (CPU SIFT, exhaustive matching, incremental mapper) on a
// small synthetic scene must register every image, and after a similarity alignment of
// the camera centres to the ground truth (Umeyama) every camera must be within 0.5 degree
// and 1% of the scene size of its true pose. This is what makes the synthetic scene a
// valid stand-in for photos: if it fails, improve the texture or the path, never the
// bounds.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "colmap_ext/sparse_io.h"
#include "fvs/synthetic/generate.h"
#include "support/test_support.h"

namespace fvs {
namespace {

namespace fs = std::filesystem;

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// CPU seconds (user + system) of this process or of its finished children: on a shared
// machine wall time says little, so both are printed.
double CpuSeconds(int who) {
  rusage usage{};
  getrusage(who, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

void RunColmapStep(const std::string& args) {
  const std::string command =
      "QT_QPA_PLATFORM=offscreen " + testing::RealColmapBinary() + " " + args;
  std::string output;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = CpuSeconds(RUSAGE_CHILDREN);
  const int status = testing::RunShell(command, &output);
  std::printf("  colmap %s: %.1f s wall, %.1f s CPU\n",
              args.substr(0, args.find(' ')).c_str(), Seconds(start),
              CpuSeconds(RUSAGE_CHILDREN) - cpu_start);
  ASSERT_EQ(status, 0) << command << "\n" << output;
}

TEST(SfmEndToEnd, RealColmapRecoversTheGroundTruthPoses) {
  testing::TempDir dir;
  SyntheticSceneOptions options;
  options.num_views = 12;  // 640x480, the default path spacing: small and fast
  options.seed = 1;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = CpuSeconds(RUSAGE_SELF);
  GenerateSyntheticScene(options, dir.path());
  std::printf("  generate %d views %dx%d: %.1f s wall, %.1f s CPU\n", options.num_views,
              options.width, options.height, Seconds(start),
              CpuSeconds(RUSAGE_SELF) - cpu_start);
  const SyntheticScene scene = BuildSyntheticScene(options);

  const std::string db = dir / "database.db";
  const std::string images = dir / "images";
  // CPU SIFT without the upsampled first octave and with at most 4096 features per image:
  // plenty for 640x480 views of a textured scene, and it keeps matching (quadratic in the
  // feature count) fast on two cores.
  RunColmapStep("feature_extractor --database_path " + db + " --image_path " + images +
                " --ImageReader.single_camera 1 --ImageReader.camera_model PINHOLE"
                " --SiftExtraction.use_gpu 0 --SiftExtraction.first_octave 0"
                " --SiftExtraction.max_num_features 4096");
  RunColmapStep("exhaustive_matcher --database_path " + db + " --SiftMatching.use_gpu 0");
  fs::create_directories(dir / "sfm");
  RunColmapStep("mapper --database_path " + db + " --image_path " + images +
                " --output_path " + (dir / "sfm"));
  ASSERT_TRUE(fs::exists(dir / "sfm/0")) << "mapper produced no model";
  EXPECT_FALSE(fs::exists(dir / "sfm/1")) << "the scene broke into several models";

  const colmap::Reconstruction model = colmap::ReadSparseModel(dir / "sfm/0");
  ASSERT_EQ(model.images.size(), static_cast<size_t>(options.num_views))
      << "not every image registered";

  // The focal length was estimated too (PINHOLE, no prior): it must come out right.
  ASSERT_EQ(model.cameras.size(), 1u);
  const double focal_error =
      std::abs(model.cameras.begin()->second.params.at(0) / scene.cameras[0].fx - 1.0);
  EXPECT_LT(focal_error, 0.02);
  std::printf("  focal length error %.3f%%\n", 100.0 * focal_error);

  // Similarity alignment (Umeyama) of the estimated camera frames to the true ones: each
  // camera contributes its centre and the tips of its three axes at a distance d (the RMS
  // spread of the centres in each model's own units). Centres alone lie on a shallow arc,
  // so a fit to them alone leaves the tilt about the arc's chord poorly determined (0.8
  // mm of centre noise over a 0.5 m sagitta is already 0.1 degree) and would blame SfM
  // for it.
  const int n = options.num_views;
  std::vector<const colmap::Image*> estimated(n);
  Eigen::Matrix3Xd est_centers(3, n), gt_centers(3, n);
  for (int i = 0; i < n; ++i) {
    estimated[i] = model.FindImageByName(scene.image_names[i]);
    ASSERT_NE(estimated[i], nullptr) << scene.image_names[i];
    est_centers.col(i) = estimated[i]->ProjectionCenter();
    gt_centers.col(i) = scene.cameras[i].Center();
  }
  auto spread = [](const Eigen::Matrix3Xd& c) {
    return std::sqrt((c.colwise() - c.rowwise().mean()).squaredNorm() / c.cols());
  };
  const double d_est = spread(est_centers), d_gt = spread(gt_centers);
  Eigen::Matrix3Xd src(3, 4 * n), dst(3, 4 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d r_est = estimated[i]->Rotation(), r_gt = scene.cameras[i].R;
    src.col(4 * i) = est_centers.col(i);
    dst.col(4 * i) = gt_centers.col(i);
    for (int a = 0; a < 3; ++a) {
      src.col(4 * i + 1 + a) = est_centers.col(i) + d_est * r_est.row(a).transpose();
      dst.col(4 * i + 1 + a) = gt_centers.col(i) + d_gt * r_gt.row(a).transpose();
    }
  }
  const Eigen::Matrix4d sim = Eigen::umeyama(src, dst, /*with_scaling=*/true);
  const Eigen::Matrix3d sR = sim.topLeftCorner<3, 3>();
  const double scale = std::cbrt(sR.determinant());
  const Eigen::Matrix3d align_rotation = sR / scale;

  double max_rotation_deg = 0, max_position = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d center = sR * est_centers.col(i) + sim.topRightCorner<3, 1>();
    const double position_error = (center - gt_centers.col(i)).norm();
    // x_est = (A^T (x_gt - t)) / s, so the estimated world->camera rotation expressed in
    // the ground-truth frame is R_est * A^T.
    const Eigen::Matrix3d rotation =
        estimated[i]->Rotation() * align_rotation.transpose();
    const double rotation_error =
        Eigen::AngleAxisd(rotation * scene.cameras[i].R.transpose()).angle() * 180.0 /
        M_PI;
    EXPECT_LT(rotation_error, 0.5) << scene.image_names[i];
    EXPECT_LT(position_error, 0.01 * scene.scene_size) << scene.image_names[i];
    max_rotation_deg = std::max(max_rotation_deg, rotation_error);
    max_position = std::max(max_position, position_error);
  }
  double max_relative_deg = 0;  // alignment-free: R_i R_j^T against the truth
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Matrix3d rel_est =
          estimated[i]->Rotation() * estimated[j]->Rotation().transpose();
      const Eigen::Matrix3d rel_gt = scene.cameras[i].R * scene.cameras[j].R.transpose();
      max_relative_deg =
          std::max(max_relative_deg,
                   Eigen::AngleAxisd(rel_est * rel_gt.transpose()).angle() * 180 / M_PI);
    }
  }
  std::printf("  max relative rotation error over all pairs %.4f deg\n",
              max_relative_deg);
  std::printf(
      "  %zu/%d registered, %zu points; max rotation error %.4f deg, max position error "
      "%.4f (%.4f%% of the scene size %.2f)\n",
      model.images.size(), options.num_views, model.points3D.size(), max_rotation_deg,
      max_position, 100.0 * max_position / scene.scene_size, scene.scene_size);
  std::printf("  total: %.1f s wall, %.1f s CPU (this process and COLMAP)\n",
              Seconds(start),
              CpuSeconds(RUSAGE_SELF) + CpuSeconds(RUSAGE_CHILDREN) - cpu_start);
}

}  // namespace
}  // namespace fvs
