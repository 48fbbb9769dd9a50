// Our own round trips of sparse models (.bin and .txt) and the faults the readers must
// name.
#include "colmap_ext/sparse_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>

#include "colmap_ext/model_fixture.h"
#include "fvs/util/atomic_file.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs::colmap {
namespace {

using fvs::testing::ExpectError;
using fvs::testing::ReadTextFile;
using fvs::testing::TempDir;
using fvs::testing::WriteTextFile;

TEST(SparseIo, BinaryRoundTripIsExactAndStable) {
  TempDir dir;
  const Reconstruction model = testing::MakeSampleModel();
  WriteSparseModelBinary(dir / "a", model);
  const Reconstruction back = ReadSparseModel(dir / "a");
  std::string why;
  EXPECT_TRUE(testing::ModelsEqual(model, back, &why)) << why;
  WriteSparseModelBinary(dir / "b", back);
  for (const char* f : {"cameras.bin", "images.bin", "points3D.bin"}) {
    EXPECT_EQ(ReadTextFile(dir / "a/" + std::string(f)),
              ReadTextFile(dir / "b/" + std::string(f)));
  }
}

TEST(SparseIo, TextRoundTripIsExact) {
  TempDir dir;
  Reconstruction model = testing::MakeSampleModel();
  // Awkward doubles must survive text too.
  model.images.begin()->second.tvec = Eigen::Vector3d(0.1, 1.0 / 3.0, -1e-300);
  model.points3D.begin()->second.xyz =
      Eigen::Vector3d(1e17 + 3, -2.5e-8, 123456.789012345678);
  WriteSparseModelText(dir / "t", model);
  EXPECT_FALSE(std::filesystem::exists(dir / "t/cameras.bin"));
  const Reconstruction back = ReadSparseModel(dir / "t");
  std::string why;
  EXPECT_TRUE(testing::ModelsEqual(model, back, &why)) << why;
  const std::string images = ReadTextFile(dir / "t/images.txt");
  EXPECT_NE(images.find(" -1\n"), std::string::npos) << "invalid point3D ids are -1";
  EXPECT_NE(images.find("# Number of images: 22, mean observations per image: 20\n"),
            std::string::npos);
}

TEST(SparseIo, ImageWithoutPointsHasAnEmptyLineInText) {
  TempDir dir;
  Reconstruction model = testing::MakeSampleModel(1);
  model.points3D.clear();
  for (auto& [id, image] : model.images) image.points2D.clear();
  WriteSparseModelText(dir / "t", model);
  const Reconstruction back = ReadSparseModelText(dir / "t");
  std::string why;
  EXPECT_TRUE(testing::ModelsEqual(model, back, &why)) << why;
}

TEST(SparseIo, PinholeForAndFindByName) {
  const Reconstruction model = testing::MakeSampleModel();
  const Image* image = model.FindImageByName("img_3.png");
  ASSERT_NE(image, nullptr);
  EXPECT_EQ(image->camera_id, 2u);  // PINHOLE
  const PinholeCamera cam = model.PinholeFor(image->image_id);
  EXPECT_EQ(cam.fx, 510);
  EXPECT_EQ(cam.cy, 239.5);
  EXPECT_TRUE(cam.IsValid());
  // The 2D point made by our PINHOLE projection equals the pinhole camera's projection.
  const Eigen::Vector3d world = model.points3D.at(image->points2D[0].point3D_id).xyz;
  EXPECT_NEAR(
      (cam.CameraToPixel(cam.WorldToCamera(world)) - image->points2D[0].xy).norm(), 0,
      1e-9);
  EXPECT_EQ(model.FindImageByName("nope.png"), nullptr);
  ExpectError([&] { model.PinholeFor(5); }, {"SIMPLE_RADIAL", "undistort"});
  ExpectError([&] { model.PinholeFor(999); }, {"999"});
}

class SparseIoFaults : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::MakeSampleModel(1);
    WriteSparseModelBinary(dir_ / "bin", testing::MakeSampleModel(1));
    WriteSparseModelText(dir_ / "txt", testing::MakeSampleModel(1));
  }
  std::string Bin(const std::string& f) { return dir_ / ("bin/" + f); }
  std::string Txt(const std::string& f) { return dir_ / ("txt/" + f); }
  TempDir dir_;
};

TEST_F(SparseIoFaults, TruncatedBinaryFilesAtEveryCut) {
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string path = Bin(name);
    const std::string original = ReadTextFile(path);
    for (size_t cut : {size_t(0), size_t(3), size_t(8), size_t(13), original.size() / 2,
                       original.size() - 1}) {
      WriteTextFile(path, original.substr(0, cut));
      ExpectError([&] { ReadSparseModelBinary(dir_ / "bin"); }, {path});
    }
    WriteTextFile(path, original + "x");
    ExpectError([&] { ReadSparseModelBinary(dir_ / "bin"); }, {path, "trailing"});
    WriteTextFile(path, original);
  }
  EXPECT_NO_THROW(ReadSparseModelBinary(dir_ / "bin"));
}

TEST_F(SparseIoFaults, HugeCountDoesNotAllocate) {
  std::string data = ReadTextFile(Bin("points3D.bin"));
  const uint64_t huge = uint64_t(1) << 60;
  std::memcpy(data.data(), &huge, 8);
  WriteTextFile(Bin("points3D.bin"), data);
  ExpectError([&] { ReadSparseModelBinary(dir_ / "bin"); },
              {"points3D.bin", "number of 3D points"});
}

TEST_F(SparseIoFaults, UnknownCameraModelAndWrongParameterCount) {
  std::string data = ReadTextFile(Bin("cameras.bin"));
  const int32_t bad = 42;
  std::memcpy(data.data() + 8 + 4, &bad, 4);  // first camera's model id
  WriteTextFile(Bin("cameras.bin"), data);
  ExpectError([&] { ReadSparseModel(dir_ / "bin"); },
              {"cameras.bin", "unknown camera model id 42"});

  std::string text = ReadTextFile(Txt("cameras.txt"));
  const std::string with_bad_model =
      std::string(text).replace(text.find("SIMPLE_RADIAL "), 13, "FANCY_MODEL");
  WriteTextFile(Txt("cameras.txt"), with_bad_model);
  ExpectError([&] { ReadSparseModel(dir_ / "txt"); },
              {"cameras.txt", "unknown camera model 'FANCY_MODEL'"});
  WriteTextFile(Txt("cameras.txt"), text + "99 PINHOLE 640 480 500 500 320\n");
  ExpectError([&] { ReadSparseModel(dir_ / "txt"); },
              {"cameras.txt", "PINHOLE needs 4 parameters, got 3"});
  WriteTextFile(Txt("cameras.txt"), text + "99 PINHOLE 640 480 500 500 320 abc\n");
  ExpectError([&] { ReadSparseModel(dir_ / "txt"); },
              {"cameras.txt", "bad camera parameter 'abc'"});
}

TEST_F(SparseIoFaults, NonFinitePoses) {
  std::string data = ReadTextFile(Bin("images.bin"));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(data.data() + 8 + 4 + 8 * 4, &nan, 8);  // first image's tvec x
  WriteTextFile(Bin("images.bin"), data);
  ExpectError([&] { ReadSparseModel(dir_ / "bin"); }, {"images.bin", "non-finite pose"});

  std::string text = ReadTextFile(Txt("images.txt"));
  const size_t line = text.find("\n1 ") + 3;  // image 1's qw
  text.replace(line, text.find(' ', line) - line, "inf");
  WriteTextFile(Txt("images.txt"), text);
  ExpectError([&] { ReadSparseModel(dir_ / "txt"); }, {"images.txt", "non-finite pose"});
}

TEST_F(SparseIoFaults, DanglingReferencesAndMissingFiles) {
  Reconstruction model = testing::MakeSampleModel(1);
  model.images.at(1).camera_id = 77;
  ExpectError([&] { WriteSparseModelBinary(dir_ / "new", model); },
              {"missing camera 77"});
  EXPECT_FALSE(std::filesystem::exists(dir_ / "new/cameras.bin")) << "no partial output";

  model = testing::MakeSampleModel(1);
  model.points3D.at(1).track.push_back({1, 9999});
  ExpectError([&] { model.Check("m"); }, {"m: point3D 1", "9999"});
  model.points3D.at(1).track.back() = {500, 0};
  ExpectError([&] { model.Check("m"); }, {"missing image 500"});

  // A text track that points at a 2D point the image does not have.
  std::string text = ReadTextFile(Txt("points3D.txt"));
  WriteTextFile(Txt("points3D.txt"), text + "999 1 2 3 4 5 6 0.5 1 4000\n");
  ExpectError([&] { ReadSparseModel(dir_ / "txt"); }, {"points3D.txt", "point3D 999"});

  std::filesystem::remove(Bin("images.bin"));
  ExpectError([&] { ReadSparseModel(dir_ / "bin"); }, {"images.bin", "cannot open"});
  ExpectError([&] { ReadSparseModel(dir_ / "nothing"); }, {"nothing", "does not exist"});
}

TEST_F(SparseIoFaults, WriterKeepsOldFilesWhenItRefuses) {
  const std::string before = ReadTextFile(Bin("cameras.bin"));
  Reconstruction model = testing::MakeSampleModel(1);
  model.cameras.at(3).params.pop_back();
  ExpectError([&] { WriteSparseModelBinary(dir_ / "bin", model); },
              {"needs 4 parameters"});
  EXPECT_EQ(ReadTextFile(Bin("cameras.bin")), before);
  model = testing::MakeSampleModel(1);
  model.images.at(2).name = "has space.png";
  ExpectError([&] { WriteSparseModelText(dir_ / "txt2", model); }, {"white space"});
  for (const auto& entry : std::filesystem::directory_iterator(dir_.path() + "/bin")) {
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

}  // namespace
}  // namespace fvs::colmap
