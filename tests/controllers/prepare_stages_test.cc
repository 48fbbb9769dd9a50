#include "fvs/controllers/prepare_stages.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "colmap_ext/reconstruction.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs {
namespace {

TEST(PrepareStages, RecognisesVideoFrames) {
  std::vector<std::string> frames, photos;
  for (int i = 0; i < 40; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%05d.jpg", i + 7);
    frames.push_back(name);
  }
  EXPECT_TRUE(LooksLikeVideoFrames(frames));
  photos = {"IMG_1001.JPG", "IMG_1007.JPG", "IMG_1013.JPG", "IMG_1020.JPG",
            "IMG_1031.JPG", "IMG_1040.JPG", "IMG_1047.JPG", "IMG_1052.JPG",
            "IMG_1060.JPG", "IMG_1077.JPG", "IMG_1079.JPG"};
  EXPECT_FALSE(LooksLikeVideoFrames(photos));  // numbered, not consecutive
  EXPECT_FALSE(LooksLikeVideoFrames({"a.jpg", "b.jpg"}));
  std::vector<std::string> mixed = frames;
  mixed[3] = "castle.jpg";
  EXPECT_FALSE(LooksLikeVideoFrames(mixed));
}

std::vector<std::string> NumberedNames(int n, const char* format) {
  std::vector<std::string> names;
  for (int i = 0; i < n; ++i) {
    char name[64];
    std::snprintf(name, sizeof(name), format, i);
    names.push_back(name);
  }
  return names;
}

// Name order is no evidence of a video: up to the affordable size every pair is matched,
// numbered or not; only long runs of consecutive frames get sequential matching.
TEST(PrepareStages, AutoMatchingIsExhaustiveWhileAffordable) {
  // The set that lost 7 of 25 photos to sequential matching.
  EXPECT_EQ(ChooseMatcher(NumberedNames(25, "%02d.jpg"), false).type, "exhaustive");
  EXPECT_EQ(ChooseMatcher(NumberedNames(150, "frame_%05d.png"), false).type,
            "exhaustive");
  EXPECT_EQ(
      ChooseMatcher(NumberedNames(kMaxExhaustiveImages, "frame_%05d.png"), false).type,
      "exhaustive");
  const MatcherChoice video =
      ChooseMatcher(NumberedNames(kMaxExhaustiveImages + 1, "frame_%05d.png"), false);
  EXPECT_EQ(video.type, "sequential");
  EXPECT_NE(video.reason.find("loop closure"), std::string::npos) << video.reason;
  // With matching on a GPU, exhaustive goes further.
  EXPECT_EQ(ChooseMatcher(NumberedNames(600, "frame_%05d.png"), true).type, "exhaustive");
  EXPECT_EQ(ChooseMatcher(NumberedNames(1200, "frame_%05d.png"), true).type,
            "sequential");
  // Many unordered photos: still every pair (nothing cheaper registers them).
  std::vector<std::string> unordered;
  for (int i = 0; i < 300; ++i)
    unordered.push_back("IMG_" + std::to_string(1000 + 7 * i) + ".JPG");
  const MatcherChoice photos = ChooseMatcher(unordered, false);
  EXPECT_EQ(photos.type, "exhaustive");
  EXPECT_NE(photos.reason.find("44850 pairs"), std::string::npos) << photos.reason;
}

TEST(PrepareStages, SequentialPairsCloseLoops) {
  const int n = 400;
  const std::vector<std::pair<int, int>> pairs = SequentialPairs(n);
  const std::set<std::pair<int, int>> set(pairs.begin(), pairs.end());
  EXPECT_EQ(set.size(), pairs.size());
  for (const auto& [i, j] : pairs) {
    EXPECT_LT(i, j);
    EXPECT_LT(j, n);
  }
  EXPECT_TRUE(set.count({10, 20}));  // the next 10
  EXPECT_FALSE(set.count({10, 21}));
  EXPECT_TRUE(set.count({10, 10 + 256}));  // quadratic overlap
  // Loop closure: the first and the last frame, and keyframes far apart.
  EXPECT_TRUE(set.count({0, n - 1}));
  EXPECT_TRUE(set.count({8, 392}));
  // Far fewer than every pair.
  EXPECT_LT(pairs.size(), static_cast<size_t>(n) * (n - 1) / 2 / 5);
  EXPECT_TRUE(SequentialPairs(1).empty());
  EXPECT_EQ(SequentialPairs(2), (std::vector<std::pair<int, int>>{{0, 1}}));
}

TEST(PrepareStages, RetriesExhaustiveOnlyWhenPhotosWereLost) {
  EXPECT_TRUE(ShouldRetryExhaustive("sequential", 18, 25));
  EXPECT_FALSE(ShouldRetryExhaustive("sequential", 25, 25));
  EXPECT_FALSE(ShouldRetryExhaustive("exhaustive", 18, 25));  // nothing more thorough
}

TEST(PrepareStages, WarnsWhenUndistortionShrinksTheImages) {
  colmap::Reconstruction sfm, undistorted;
  sfm.cameras[1] = {
      1, 2, 800, 800, {562, 400, 400, -0.166}};  // ethiopian_head's estimate
  sfm.cameras[2] = {2, 2, 1600, 1200, {1200, 800, 600, -0.01}};
  undistorted.cameras[1] = {1, 1, 160, 160, {112, 112, 80, 80}};  // COLMAP's min_scale
  undistorted.cameras[2] = {
      2, 1, 780, 590, {590, 590, 390, 295}};  // at max_image_size 800
  const std::vector<std::string> warnings =
      ShrunkenUndistortionWarnings(sfm, undistorted, 800);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("camera 1 from 800x800 to 160x160"), std::string::npos)
      << warnings[0];
  EXPECT_TRUE(ShrunkenUndistortionWarnings(sfm, sfm, 0).empty());
}

TEST(PrepareStages, HoldoutListFromCommasOrFile) {
  EXPECT_TRUE(ParseHoldoutList("").empty());
  EXPECT_EQ(ParseHoldoutList("a.jpg, b.jpg,,"),
            (std::set<std::string>{"a.jpg", "b.jpg"}));
  testing::TempDir dir;
  testing::WriteTextFile(dir / "list.txt", "# targets\nx.png\n\n  y.png  \n");
  EXPECT_EQ(ParseHoldoutList(dir / "list.txt"),
            (std::set<std::string>{"x.png", "y.png"}));
}

TEST(PrepareStages, ListImageFilesRejectsEmptyAndMissingFolders) {
  testing::TempDir dir;
  EXPECT_THROW(ListImageFiles(dir / "missing"), Error);
  EXPECT_THROW(ListImageFiles(dir.path()), Error);
  testing::WriteTextFile(dir / "b.PNG", "");
  testing::WriteTextFile(dir / "a.jpg", "");
  testing::WriteTextFile(dir / "notes.txt", "");
  EXPECT_EQ(ListImageFiles(dir.path()), (std::vector<std::string>{"a.jpg", "b.PNG"}));
}

// Three images seeing common points; "c" held out: it must appear nowhere in the configs.
TEST(PrepareStages, StereoConfigsKeepHoldoutsOutOfTheGeometry) {
  testing::TempDir dir;
  colmap::Reconstruction rec;
  colmap::Camera camera;
  camera.camera_id = 1;
  camera.model_id = 1;  // PINHOLE
  camera.width = 100;
  camera.height = 80;
  camera.params = {90, 90, 50, 40};
  rec.cameras[1] = camera;
  const char* names[] = {"a.png", "b.png", "c.png", "d.png"};
  for (uint32_t id = 1; id <= 4; ++id) {
    colmap::Image image;
    image.image_id = id;
    image.camera_id = 1;
    image.name = names[id - 1];
    image.tvec = Eigen::Vector3d(0.1 * id, 0, 0);
    for (int p = 0; p < 10; ++p) {
      colmap::Point2D pt;
      pt.xy = Eigen::Vector2d(10 + p, 10);
      pt.point3D_id = p + 1;
      image.points2D.push_back(pt);
    }
    rec.images[id] = image;
  }
  for (uint64_t p = 1; p <= 10; ++p) {
    colmap::Point3D point;
    point.xyz = Eigen::Vector3d(0.1 * p, 0, 5);
    // a, b, c see every point; d sees only the first three.
    for (uint32_t id = 1; id <= 4; ++id) {
      if (id == 4 && p > 3) continue;
      point.track.push_back({id, static_cast<uint32_t>(p - 1)});
    }
    rec.points3D[p] = point;
  }
  colmap::WriteSparseModelBinary(dir / "sparse", rec);
  WriteStereoConfigs(dir.path(), {"c.png"});
  const std::string patch_match = testing::ReadTextFile(dir / "stereo/patch-match.cfg");
  const std::string fusion = testing::ReadTextFile(dir / "stereo/fusion.cfg");
  EXPECT_EQ(patch_match.find("c.png"), std::string::npos) << patch_match;
  EXPECT_EQ(fusion.find("c.png"), std::string::npos) << fusion;
  EXPECT_EQ(fusion, "a.png\nb.png\nd.png\n");
  // Sources ranked by shared points: for a, b (10 shared) before d (3 shared).
  EXPECT_NE(patch_match.find("a.png\nb.png, d.png\n"), std::string::npos) << patch_match;
}

}  // namespace
}  // namespace fvs
