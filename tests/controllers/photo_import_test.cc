// Photos as phones make them (controllers/photo_import.h): a photo stored rotated with an
// EXIF orientation tag and a HEIC photo are written upright as JPEGs with their EXIF
// camera kept; the others are linked; the photos are grouped by camera. The files are
// made with oiiotool (OpenImageIO, which reads and writes HEIF here).
#include "fvs/controllers/photo_import.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "colmap_ext/image_io.h"
#include "colmap_ext/photo_metadata.h"
#include "support/test_support.h"

namespace fvs::testing {
namespace {

namespace fs = std::filesystem;

// A 64x48 grey photo, red in its top-left 16x16 corner, as the user sees it.
std::string Oiiotool() {
  return "oiiotool --create 64x48 3 --fill:color=1,0,0 16x16+0+0";
}

class PhotoImport : public ::testing::Test {
 protected:
  void SetUp() override {
    if (RunShell("command -v oiiotool >/dev/null") != 0) GTEST_SKIP() << "no oiiotool";
    const std::string in = dir_ / "in";
    fs::create_directories(in);
    const std::string phone_a =
        " --attrib Make PhoneCo --attrib Model A1"
        " --attrib Exif:FocalLength 4.2";
    std::string log;
    // a.jpg: upright. b.jpg: stored turned 90 degrees counter-clockwise, with the tag
    // (6: turn it clockwise to view). c.heic: HEIF. d.jpg: another camera.
    ASSERT_EQ(RunShell(Oiiotool() + phone_a + " -o " + in + "/a.jpg", &log), 0) << log;
    ASSERT_EQ(RunShell(Oiiotool() + phone_a + " --rotate270 --attrib Orientation 6 -o " +
                           in + "/b.jpg",
                       &log),
              0)
        << log;
    ASSERT_EQ(RunShell(Oiiotool() + phone_a + " -o " + in + "/c.heic", &log), 0) << log;
    ASSERT_EQ(RunShell("oiiotool --create 80x60 3 --attrib Make Other --attrib Model B2"
                       " -o " +
                           in + "/d.jpg",
                       &log),
              0)
        << log;
  }
  TempDir dir_;
};

TEST_F(PhotoImport, RotatedAndHeifPhotosAreWrittenUprightWithTheirCamera) {
  const std::string in = dir_ / "in";
  const PhotoImportPlan plan = PlanPhotoImport(in, {"a.jpg", "b.jpg", "c.heic", "d.jpg"});
  ASSERT_EQ(plan.photos.size(), 4u);
  EXPECT_TRUE(plan.needed());
  EXPECT_EQ(plan.num_converted(), 2);
  EXPECT_FALSE(plan.photos[0].convert);
  EXPECT_TRUE(plan.photos[1].convert);
  EXPECT_EQ(plan.photos[1].metadata.orientation, 6);
  EXPECT_EQ(plan.photos[1].metadata.width(), 64);
  EXPECT_EQ(plan.photos[1].metadata.height(), 48);
  EXPECT_EQ(plan.photos[2].name, "c.heic.jpg");
  EXPECT_EQ(plan.NameOf("c.heic"), "c.heic.jpg");
  EXPECT_EQ(plan.NameOf("c.heic.jpg"), "c.heic.jpg");
  EXPECT_THROW(plan.NameOf("nosuch.jpg"), Error);
  // a, b and c are one phone (same make, model, focal length and upright size), d
  // another.
  const auto groups = plan.CameraGroups();
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0], (std::vector<std::string>{"a.jpg", "b.jpg", "c.heic.jpg"}));
  EXPECT_EQ(groups[1], (std::vector<std::string>{"d.jpg"}));

  const std::string out = dir_ / "out";
  ImportPhotos(plan, in, out);
  EXPECT_TRUE(fs::is_symlink(out + "/a.jpg"));
  EXPECT_TRUE(fs::is_symlink(out + "/d.jpg"));
  for (const char* name : {"b.jpg", "c.heic.jpg"}) {
    SCOPED_TRACE(name);
    const std::string path = out + "/" + name;
    ASSERT_TRUE(fs::is_regular_file(fs::symlink_status(path)));
    const colmap::PhotoMetadata m = colmap::ReadPhotoMetadata(path);
    EXPECT_EQ(m.format, "jpeg");
    EXPECT_EQ(m.orientation, 1);
    EXPECT_EQ(m.stored_width, 64);
    EXPECT_EQ(m.stored_height, 48);
    EXPECT_EQ(m.make, "PhoneCo");
    EXPECT_EQ(m.model, "A1");
    EXPECT_NEAR(m.focal_length_mm, 4.2, 1e-3);
    // Upright: the red corner is top-left again, the rest grey-black.
    const Image image = colmap::ReadImage(path);
    EXPECT_GT(image.at(4, 4, 0), 0.8f);
    EXPECT_LT(image.at(4, 4, 1), 0.2f);
    EXPECT_LT(image.at(60, 4, 0), 0.2f);
    EXPECT_LT(image.at(4, 44, 0), 0.2f);
  }
}

TEST_F(PhotoImport, UprightJpegsNeedNoImport) {
  const PhotoImportPlan plan = PlanPhotoImport(dir_ / "in", {"a.jpg", "d.jpg"});
  EXPECT_FALSE(plan.needed());
  EXPECT_EQ(plan.photos[0].name, "a.jpg");
  ExpectError(
      [&] {
        PlanPhotoImport(dir_ / "in", {"a.jpg", "missing.jpg"});
      },
      {"missing.jpg", "cannot read image"});
}

}  // namespace
}  // namespace fvs::testing
