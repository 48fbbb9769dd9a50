// Blurry and duplicate photos (scene/photo_quality.h): the sharpness falls with blur
// below the rule's ratio, stays finite on flat, tiny and non-finite photos; duplicate
// poses are found by distance and direction; the report round-trips and a broken one is
// one error line.
#include "fvs/scene/photo_quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fvs/util/image_resize.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

Image Noise(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Image image(width, height, 3);
  for (float& v : image.data) v = u(rng);
  return image;
}

// A box blur of radius r, `passes` times (about a Gaussian of sigma r sqrt(passes / 3)).
Image Blur(Image image, int r, int passes) {
  for (int p = 0; p < passes; ++p) image = BoxBlur(image, r);
  return image;
}

TEST(PhotoQuality, BlurLowersSharpnessBelowTheRule) {
  // Texture at several scales: noise blurred a little, as a photo's detail.
  const Image photo = Blur(Noise(320, 240, 1), 1, 1);
  const double sharp = Sharpness(photo);
  const double blurred = Sharpness(Blur(photo, 2, 2));
  EXPECT_GT(sharp, 0);
  EXPECT_LT(blurred, PhotoQualityOptions().blur_ratio * sharp);
  // The same content at another size scores alike (photos are compared at one size).
  EXPECT_NEAR(Sharpness(Blur(Noise(1024, 768, 2), 1, 1)) /
                  Sharpness(Blur(Noise(1024, 768, 3), 1, 1)),
              1.0, 0.1);
}

TEST(PhotoQuality, FlatTinyAndNonFinitePhotosAreFinite) {
  Image flat(64, 48, 3);
  EXPECT_EQ(Sharpness(flat), 0.0);
  EXPECT_EQ(Sharpness(Image(2, 2, 3)), 0.0);
  Image bad = Noise(64, 48, 4);
  bad.at(10, 10, 0) = NAN;
  bad.at(20, 10, 1) = INFINITY;
  EXPECT_TRUE(std::isfinite(Sharpness(bad)));
}

TEST(PhotoQuality, NearDuplicatesByDistanceAndDirection) {
  std::vector<Eigen::Vector3d> centres, directions;
  for (int i = 0; i < 8; ++i) {  // one metre apart, all looking along +z
    centres.push_back({static_cast<double>(i), 0, 0});
    directions.push_back(Eigen::Vector3d::UnitZ());
  }
  centres.push_back({3.01, 0, 0});  // 8: a second shot of 3
  directions.push_back(Eigen::Vector3d(0.01, 0, 1).normalized());
  centres.push_back({5.0, 0, 0});  // 9: at 5, but looking sideways
  directions.push_back(Eigen::Vector3d::UnitX());
  const auto pairs = NearDuplicatePairs(centres, directions, PhotoQualityOptions());
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(3, 8));
  // Every camera at one point (a spacing of zero): only equal poses pair.
  const std::vector<Eigen::Vector3d> same(3, Eigen::Vector3d(1, 2, 3));
  const std::vector<Eigen::Vector3d> looks = {
      Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  EXPECT_EQ(NearDuplicatePairs(same, looks, PhotoQualityOptions()).size(), 1u);
  EXPECT_TRUE(NearDuplicatePairs({}, {}, PhotoQualityOptions()).empty());
}

TEST(PhotoQuality, ReportRoundTripsAndSaysWhatIsBlurry) {
  TempDir dir;
  PhotoQualityReport report;
  report.median_sharpness = 0.02;
  report.photos = {{"a.jpg", 0.02, 1.0, false, {"c.jpg"}},
                   {"b.jpg", 0.002, 0.1, true, {}},
                   {"c.jpg", 0.021, 1.05, false, {"a.jpg"}}};
  EXPECT_EQ(report.Summary(),
            "1 of 3 photos blurry: b.jpg (10 % of the median); used as sources only "
            "where no sharp photo sees; 1 near-duplicate pair (a.jpg = c.jpg)");
  WritePhotoQualityReport(dir / "q.json", report);
  const PhotoQualityReport back = ReadPhotoQualityReport(dir / "q.json");
  ASSERT_EQ(back.photos.size(), 3u);
  EXPECT_TRUE(back.photos[1].blurry);
  EXPECT_EQ(back.photos[0].duplicates, std::vector<std::string>{"c.jpg"});
  EXPECT_EQ(back.Summary(), report.Summary());
  EXPECT_TRUE(ReadPhotoQualityReport(dir / "missing.json").photos.empty());
  WriteTextFile(dir / "bad.json", "{\"photos\": 3}");
  ExpectError([&] { ReadPhotoQualityReport(dir / "bad.json"); },
              {"bad.json", "not a photo quality report"});
  PhotoQualityOptions bad;
  bad.blur_ratio = 1.5;
  ExpectError([&] { bad.Check(); }, {"--PhotoQuality.blur_ratio"});
}

}  // namespace
}  // namespace fvs::testing
