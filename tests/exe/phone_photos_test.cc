// Photos as phones make them (issue 42, items 1-3), through the front door: a set in
// which half the photos are stored rotated with the EXIF orientation tag set and two are
// HEIC registers and scores like the same set stored upright as JPEGs; a set from two
// cameras of different size and focal length registers with one camera per device, and
// its blurred photos are listed (item 4). The
// photos are ten generated views, written with oiiotool (OpenImageIO reads and writes
// HEIF here).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "colmap_ext/image_io.h"
#include "colmap_ext/sparse_io.h"
#include "fvs/eval/report.h"
#include "fvs/scene/photo_quality.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

namespace fs = std::filesystem;

std::string Colmap() {
  return "QT_QPA_PLATFORM=offscreen FVS_QUIET=1 OMP_WAIT_POLICY=PASSIVE '" +
         FrontDoorBinary() + "'";
}

std::string Frame(int i) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%04d", i);
  return name;
}

// Prepares `photos` into `ws` holding out frame 8, evaluates `ulr` on it into `eval`;
// returns its PSNR (NaN on failure, with the log in *log).
double PrepareAndScore(const std::string& photos, const std::string& holdout,
                       const std::string& ws, const std::string& eval, std::string* log) {
  if (RunShell(Colmap() + " view_synthesis_prepare --image_path " + photos +
                   " --workspace_path " + ws + " --holdout_images " + holdout +
                   " --Stereo.max_image_size 160 2>&1",
               log) != 0 ||
      RunShell(Colmap() + " view_synthesis_eval --workspace_path " + ws +
                   " --output_path " + eval + " 2>&1",
               log) != 0) {
    return NAN;
  }
  for (const eval::ViewResult& r : eval::ReadResultsCsv(eval + "/results.csv")) {
    if (r.ok() && r.target.rfind(Frame(8), 0) == 0) return r.psnr;
  }
  return NAN;
}

class PhonePhotos : public ::testing::Test {
 protected:
  void SetUp() override {
    if (RunShell("command -v oiiotool >/dev/null") != 0) GTEST_SKIP() << "no oiiotool";
    std::string log;
    ASSERT_EQ(
        RunShell(Colmap() + " view_synthesis_synthetic --output_path " + dir_ / "scene" +
                     " --SyntheticScene.num_views 10 --SyntheticScene.width 320"
                     " --SyntheticScene.height 240",
                 &log),
        0)
        << log;
  }
  // oiiotool from frame i of the generated scene, with `ops`, to `target`.
  void Convert(int i, const std::string& ops, const std::string& target) {
    std::string log;
    ASSERT_EQ(RunShell("oiiotool " + dir_ / "scene/images/" + Frame(i) + ".png " + ops +
                           " -o " + target,
                       &log),
              0)
        << log;
  }
  TempDir dir_;
};

TEST_F(PhonePhotos, RotatedAndHeicPhotosRegisterAndScoreAsUprightJpegs) {
  const std::string upright = dir_ / "upright", phone = dir_ / "phone";
  fs::create_directories(upright);
  fs::create_directories(phone);
  const std::string exif = " --attrib Make PhoneCo --attrib Model A1";
  for (int i = 0; i < 10; ++i) {
    Convert(i, exif, upright + "/" + Frame(i) + ".jpg");
    if (i % 2 == 0) {  // stored turned 90 degrees, tagged to be turned back
      Convert(i, exif + " --rotate270 --attrib Orientation 6",
              phone + "/" + Frame(i) + ".jpg");
    } else if (i == 1 || i == 3) {
      Convert(i, exif, phone + "/" + Frame(i) + ".heic");
    } else {
      fs::copy_file(upright + "/" + Frame(i) + ".jpg", phone + "/" + Frame(i) + ".jpg");
    }
  }
  std::string log;
  const double upright_psnr =
      PrepareAndScore(upright, Frame(8) + ".jpg", dir_ / "ws_u", dir_ / "eval_u", &log);
  ASSERT_TRUE(std::isfinite(upright_psnr)) << log;
  const double phone_psnr =
      PrepareAndScore(phone, Frame(8) + ".jpg", dir_ / "ws_p", dir_ / "eval_p", &log);
  ASSERT_TRUE(std::isfinite(phone_psnr)) << log;

  const auto u = colmap::ReadSparseModel(dir_ / "ws_u/sparse");
  const auto p = colmap::ReadSparseModel(dir_ / "ws_p/sparse");
  EXPECT_EQ(u.images.size(), 10u);
  EXPECT_EQ(p.images.size(), 10u);
  EXPECT_EQ(p.cameras.size(), 1u);
  EXPECT_NE(p.FindImageByName(Frame(1) + ".heic.jpg"), nullptr);
  // Every photo upright in the workspace: as wide as the generated views.
  for (const auto& [id, image] : p.images) {
    const auto& camera = p.cameras.at(image.camera_id);
    EXPECT_GT(camera.width, camera.height) << image.name;
  }
  EXPECT_TRUE(fs::is_regular_file(
      fs::symlink_status(dir_ / "ws_p/fvs/photos/" + Frame(0) + ".jpg")));
  // The same held-out score within noise (two JPEG encodings of the rotated photos, and
  // SfM's own randomness).
  EXPECT_NEAR(phone_psnr, upright_psnr, 1.0);
  std::printf("held-out %s.jpg, ulr PSNR: upright %.2f dB, phone %.2f dB\n",
              Frame(8).c_str(), upright_psnr, phone_psnr);
}

// Also item 4: two photos of the first camera blurred; prepare lists them and marks them
// in W/fvs/photo_quality.json (compared within their camera), and nothing else.
TEST_F(PhonePhotos, TwoCamerasGetOneCameraEachAndBlurryPhotosAreListed) {
  const std::string mixed = dir_ / "mixed";
  fs::create_directories(mixed);
  for (int i = 0; i < 10; ++i) {
    // The second camera: a smaller sensor, photos of 240x180 with a shorter lens.
    std::string ops =
        i % 2 == 0
            ? " --attrib Make PhoneCo --attrib Model A1 --attrib Exif:FocalLength 5"
            : " --attrib Make Other --attrib Model B2 --attrib Exif:FocalLength 4"
              " --resize 240x180";
    if (i == 2 || i == 6) ops += " --blur 7x7";
    Convert(i, ops, mixed + "/" + Frame(i) + ".jpg");
  }
  std::string log;
  ASSERT_EQ(RunShell(Colmap() + " view_synthesis_prepare --image_path " + mixed +
                         " --workspace_path " + dir_ / "ws" +
                         " --Stereo.max_image_size 160 2>&1",
                     &log),
            0)
      << log;
  const auto rec = colmap::ReadSparseModel(dir_ / "ws/sfm/0");
  EXPECT_EQ(rec.images.size(), 10u);
  ASSERT_EQ(rec.cameras.size(), 2u);
  for (const auto& [id, image] : rec.images) {
    const int width = static_cast<int>(rec.cameras.at(image.camera_id).width);
    const int frame = std::stoi(image.name.substr(6, 4));
    EXPECT_EQ(width, frame % 2 == 0 ? 320 : 240) << image.name;
  }
  const PhotoQualityReport quality =
      ReadPhotoQualityReport(dir_ / "ws/fvs/photo_quality.json");
  ASSERT_EQ(quality.photos.size(), rec.images.size());
  for (const PhotoQuality& q : quality.photos) {
    const bool blurred = q.name == Frame(2) + ".jpg" || q.name == Frame(6) + ".jpg";
    EXPECT_EQ(q.blurry, blurred) << q.name << " at " << q.relative << " of the median";
  }
  const size_t line = log.find("Photos: 2 of 10 photos blurry: ");
  ASSERT_NE(line, std::string::npos) << log;
  std::printf("%s\n", log.substr(line, log.find('\n', line) - line).c_str());
}

}  // namespace
}  // namespace fvs::testing
