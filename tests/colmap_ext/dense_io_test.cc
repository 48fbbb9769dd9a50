// Depth/normal maps (.bin), fused.ply.vis, image files and dense-workspace checks.
#include "colmap_ext/dense_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "colmap_ext/image_io.h"
#include "colmap_ext/reconstruction.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/error.h"
#include "support/test_support.h"
#include "support/tiled_tiff.h"

namespace fvs::colmap {
namespace {

using fvs::testing::ExpectError;
using fvs::testing::ReadTextFile;
using fvs::testing::TempDir;
using fvs::testing::WriteTextFile;

std::string Float32LE(const std::vector<float>& values) {
  std::string bytes(values.size() * 4, '\0');
  std::memcpy(bytes.data(), values.data(),
              bytes.size());  // the test host is little-endian
  return bytes;
}

TEST(DenseIo, ColmapArrayLayoutIsChannelPlanar) {
  TempDir dir;
  // 3x2 normal map: channel c of pixel (x, y) = 100 c + 10 y + x.
  fvs::Image normals(3, 2, 3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) normals.at(x, y, c) = 100.0f * c + 10.0f * y + x;
  WriteColmapArray(dir / "n.bin", normals);
  std::vector<float> planar;
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) planar.push_back(100.0f * c + 10.0f * y + x);
  EXPECT_EQ(ReadTextFile(dir / "n.bin"), "3&2&3&" + Float32LE(planar));
  const fvs::Image back = ReadColmapArray(dir / "n.bin");
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.channels, 3);
  EXPECT_EQ(back.data, normals.data);
}

TEST(DenseIo, DepthMapRoundTripIsExact) {
  TempDir dir;
  fvs::Image depth(17, 9, 1);
  for (size_t i = 0; i < depth.data.size(); ++i)
    depth.data[i] = (i % 5 == 0) ? 0.0f : 1.0f / (i + 3);
  WriteColmapArray(dir / "d.bin", depth);
  EXPECT_EQ(ReadColmapArray(dir / "d.bin").data, depth.data);
}

TEST(DenseIo, BadMapsAreNamed) {
  TempDir dir;
  const std::string path = dir / "d.bin";
  const std::string body = Float32LE(std::vector<float>(6, 1.0f));
  WriteTextFile(path, "3&2&1&" + body.substr(0, 20));
  ExpectError([&] { ReadColmapArray(path); }, {path, "truncated", "3x2x1"});
  WriteTextFile(path, "3&2&1&" + body + "xx");
  ExpectError([&] { ReadColmapArray(path); }, {path, "corrupt"});
  WriteTextFile(path, "PLY\nformat");
  ExpectError([&] { ReadColmapArray(path); }, {path, "bad header"});
  WriteTextFile(path, "3&2&");
  ExpectError([&] { ReadColmapArray(path); }, {path, "bad header"});
  WriteTextFile(path, "99999999999&2&1&");
  ExpectError([&] { ReadColmapArray(path); }, {path, "bad header"});
  WriteTextFile(path, "0&2&1&");
  ExpectError([&] { ReadColmapArray(path); }, {path, "zero"});
  std::vector<float> with_nan(6, 1.0f);
  with_nan[4] = std::numeric_limits<float>::quiet_NaN();
  WriteTextFile(path, "3&2&1&" + Float32LE(with_nan));
  ExpectError([&] { ReadColmapArray(path); }, {path, "non-finite", "(1, 1)"});
  ExpectError([&] { ReadColmapArray(dir / "missing.bin"); },
              {"missing.bin", "cannot open"});
  fvs::Image bad(2, 2, 1, 1.0f);
  bad.data[0] = std::numeric_limits<float>::infinity();
  ExpectError([&] { WriteColmapArray(dir / "out.bin", bad); }, {"out.bin", "NaN/Inf"});
  EXPECT_FALSE(std::filesystem::exists(dir / "out.bin"));
}

TEST(DenseIo, FusedVisibility) {
  TempDir dir;
  const std::vector<std::vector<uint32_t>> vis = {{0, 3, 7}, {}, {2}, {1, 2, 3, 4, 5}};
  WriteFusedVisibility(dir / "fused.ply.vis", vis);
  const std::string bytes = ReadTextFile(dir / "fused.ply.vis");
  EXPECT_EQ(bytes.size(), 8u + 4 * 4 + 4 * 9);
  uint64_t count;
  std::memcpy(&count, bytes.data(), 8);
  EXPECT_EQ(count, 4u);
  EXPECT_EQ(ReadFusedVisibility(dir / "fused.ply.vis"), vis);
  WriteTextFile(dir / "t.vis", bytes.substr(0, bytes.size() - 2));
  ExpectError([&] { ReadFusedVisibility(dir / "t.vis"); }, {"t.vis", "truncated"});
  std::string huge = bytes;
  const uint64_t big = uint64_t(1) << 62;
  std::memcpy(huge.data(), &big, 8);
  WriteTextFile(dir / "h.vis", huge);
  ExpectError([&] { ReadFusedVisibility(dir / "h.vis"); }, {"h.vis", "number of points"});
  std::string big_inner = bytes;
  const uint32_t many = 1u << 30;
  std::memcpy(big_inner.data() + 8, &many, 4);
  WriteTextFile(dir / "i.vis", big_inner);
  ExpectError([&] { ReadFusedVisibility(dir / "i.vis"); }, {"i.vis", "visibility count"});
}

TEST(ImageIo, PngRoundTripsAndConversions) {
  TempDir dir;
  fvs::Image rgb(7, 5, 3);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = (i % 256) / 255.0f;
  WriteImage(dir / "a.png", rgb);
  fvs::Image back = ReadImage(dir / "a.png");
  ASSERT_EQ(back.channels, 3);
  ASSERT_EQ(back.data.size(), rgb.data.size());
  for (size_t i = 0; i < rgb.data.size(); ++i)
    EXPECT_NEAR(back.data[i], rgb.data[i], 1e-6);
  int w = 0, h = 0;
  ReadImageSize(dir / "a.png", &w, &h);
  EXPECT_EQ(w, 7);
  EXPECT_EQ(h, 5);
  const fvs::Image grey = ReadImage(dir / "a.png", 1);
  EXPECT_EQ(grey.channels, 1);
  EXPECT_NEAR(
      grey.at(1, 0),
      0.299f * rgb.at(1, 0, 0) + 0.587f * rgb.at(1, 0, 1) + 0.114f * rgb.at(1, 0, 2),
      1e-5);
  // 16 bit keeps finer steps; values are clamped to [0, 1].
  fvs::Image fine(2, 1, 1);
  fine.data = {1000.5f / 65535.0f, 7.0f};
  WriteImage(dir / "b.png", fine, 16);
  const fvs::Image fine_back = ReadImage(dir / "b.png", 0);
  EXPECT_NEAR(fine_back.data[0], 1001.0f / 65535.0f, 1e-6);
  EXPECT_EQ(fine_back.data[1], 1.0f);
  const fvs::Image as_rgb = ReadImage(dir / "b.png", 3);
  EXPECT_EQ(as_rgb.channels, 3);
  EXPECT_EQ(as_rgb.at(1, 0, 2), 1.0f);
  // JPEG by extension.
  WriteImage(dir / "c.jpg", rgb);
  EXPECT_EQ(ReadImage(dir / "c.jpg").width, 7);
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos);
  }
}

// Decoding goes band by band (at most 2^22 values each): an image of several bands, 8 and
// 16 bits, reads back exactly, rows in their places.
TEST(ImageIo, ImagesOfSeveralBandsReadBack) {
  TempDir dir;
  fvs::Image rgb(2048, 700, 3);  // 4.3 million values: two bands
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) {
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = ((x + 7 * y + 50 * c) % 256) / 255.0f;
    }
  }
  for (const int bits : {8, 16}) {
    WriteImage(dir / "big.png", rgb, bits);
    const fvs::Image back = ReadImage(dir / "big.png");
    ASSERT_EQ(back.data.size(), rgb.data.size());
    float worst = 0.0f;
    for (size_t i = 0; i < rgb.data.size(); ++i) {
      worst = std::max(worst, std::abs(back.data[i] - rgb.data[i]));
    }
    EXPECT_LT(worst, 1e-6f) << bits << " bits";
  }
}

// Channels are converted band by band (a 185-byte TIFF of 512 channels held 1 GiB of
// floats for its RGB result: image_fuzzer): every band must still get the right ones.
TEST(ImageIo, ExtraChannelsAreDroppedInEveryBand) {
  TempDir dir;
  fvs::Image many(700, 700, 9);  // 4.4 million values: two bands
  auto value = [](int x, int y, int c) { return ((x + 3 * y + 29 * c) % 256) / 255.0f; };
  for (int y = 0; y < many.height; ++y) {
    for (int x = 0; x < many.width; ++x) {
      for (int c = 0; c < 9; ++c) many.at(x, y, c) = value(x, y, c);
    }
  }
  WriteImage(dir / "many.tif", many);
  const fvs::Image all = ReadImage(dir / "many.tif", 0);
  const fvs::Image rgb = ReadImage(dir / "many.tif", 3);
  const fvs::Image grey = ReadImage(dir / "many.tif", 1);
  ASSERT_EQ(all.channels, 9);
  ASSERT_EQ(all.data.size(), many.data.size());
  ASSERT_EQ(rgb.channels, 3);
  ASSERT_EQ(rgb.data.size(), size_t{700} * 700 * 3);
  ASSERT_EQ(grey.channels, 1);
  ASSERT_EQ(grey.data.size(), size_t{700} * 700);
  float worst = 0.0f;
  for (int y = 0; y < many.height; ++y) {
    for (int x = 0; x < many.width; ++x) {
      for (int c = 0; c < 9; ++c) {
        worst = std::max(worst, std::abs(all.at(x, y, c) - value(x, y, c)));
      }
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(rgb.at(x, y, c) - value(x, y, c)));
      }
      const float luma =
          0.299f * value(x, y, 0) + 0.587f * value(x, y, 1) + 0.114f * value(x, y, 2);
      worst = std::max(worst, std::abs(grey.at(x, y) - luma));
    }
  }
  EXPECT_LT(worst, 1e-6f);
}

TEST(ImageIo, BadImagesAreNamed) {
  TempDir dir;
  WriteTextFile(dir / "x.png", "not a png at all");
  ExpectError([&] { ReadImage(dir / "x.png"); }, {"x.png"});
  ExpectError([&] { ReadImage(dir / "none.png"); }, {"none.png"});
  ExpectError([&] { WriteImage(dir / "noext", fvs::Image(2, 2, 3)); },
              {"noext", "extension"});
  ExpectError([&] { WriteImage(dir / "e.png", fvs::Image()); }, {"e.png", "empty"});
  // A truncated PNG.
  fvs::Image rgb(40, 30, 3, 0.25f);
  WriteImage(dir / "t.png", rgb);
  const std::string bytes = ReadTextFile(dir / "t.png");
  WriteTextFile(dir / "t.png", bytes.substr(0, bytes.size() / 2));
  ExpectError([&] { ReadImage(dir / "t.png"); }, {"t.png"});
  // A header claiming 51 GB of pixels is refused before anything is allocated (an 81-byte
  // PBM found by tests/fuzz/image_fuzzer).
  WriteTextFile(dir / "huge.pbm", "P4\n2000000000 6\n" + std::string(16, '\xff'));
  ExpectError([&] { ReadImage(dir / "huge.pbm"); }, {"huge.pbm", "too large"});
  // What the result holds counts too: 100 million grey pixels fit the bound in the file
  // but not as RGB (a 17-byte PBM of 77 777 777 x 6 made 5.6 GB so).
  WriteTextFile(dir / "wide.pbm", "P4\n100000000 1\n" + std::string(16, '\xff'));
  ExpectError([&] { ReadImage(dir / "wide.pbm", 3); }, {"wide.pbm", "too large"});
  WriteTextFile(dir / "found.pbm", "P4\n077777777 6\n");
  ExpectError([&] { ReadImage(dir / "found.pbm", 1); }, {"found.pbm", "too large"});
  // A row too wide for OpenImageIO's conversion chunk of 256 rows (5.5 GB).
  WriteTextFile(dir / "wide_row.pbm", "P4\n21474837 7 21474836477");
  ExpectError([&] { ReadImage(dir / "wide_row.pbm", 1); }, {"wide_row.pbm", "too wide"});
  // Tiles claimed far larger than the image (OpenImageIO allocated a whole tile of
  // 65 536 x 65 536 pixels, 17 GB); real tile sizes read.
  WriteTextFile(dir / "tiles.tif", testing::TiledTiffBytes(65536));
  ExpectError([&] { ReadImage(dir / "tiles.tif", 1); },
              {"tiles.tif", "tiles of 65536x65536"});
  WriteTextFile(dir / "tiles64.tif", testing::TiledTiffBytes(64));
  const fvs::Image tiled = ReadImage(dir / "tiles64.tif", 1);
  ASSERT_EQ(tiled.width, 64);
  EXPECT_NEAR(tiled.data[64 * 64 - 1], 0x55 / 255.0, 1e-6);
  // A header claiming more than the file can hold (OpenImageIO reads missing TIFF strips
  // as zeros: a 179-byte TIFF of 16 396 x 13 408 pixels took 1.2 GB and 10 s under ASan).
  WriteTextFile(dir / "strips.tif", testing::StrippedTiffBytes(16396, 13408));
  ExpectError([&] { ReadImage(dir / "strips.tif", 1); },
              {"strips.tif", "16396x13408", "cannot fit in 216 bytes"});
  WriteTextFile(dir / "strips64.tif", testing::StrippedTiffBytes(64, 64));
  const fvs::Image invented = ReadImage(dir / "strips64.tif", 1);  // 19 values a byte
  ASSERT_EQ(invented.height, 64);
  EXPECT_NEAR(invented.data[0], 0x55 / 255.0, 1e-6);
  EXPECT_EQ(invented.data.back(), 0.0f);  // a strip the file lacks
  // Width times height times channels past 2^63 (undefined behaviour in the first version
  // of the bound: image_fuzzer, 33 executions in).
  WriteTextFile(dir / "max.pbm", "P4\n2147483647 2147483647\n");
  ExpectError([&] { ReadImage(dir / "max.pbm", 3); }, {"max.pbm", "too large"});
}

TEST(Workspace, PathsAndChecks) {
  TempDir dir;
  const DenseWorkspace ws(dir / "w");
  EXPECT_EQ(ws.DepthMapPath("a/b.jpg", "geometric"),
            dir / "w/stereo/depth_maps/a/b.jpg.geometric.bin");
  ExpectError([&] { CheckDenseWorkspace(ws); }, {"w", "does not exist"});
  CreateDirectories(ws.ImagesDir());
  ExpectError([&] { CheckDenseWorkspace(ws); }, {"no sparse model"});
  CreateDirectories(ws.SparseDir());
  WriteTextFile(ws.SparseDir() + "/cameras.bin", "");
  WriteTextFile(ws.SparseDir() + "/images.bin", "");
  EXPECT_NO_THROW(CheckDenseWorkspace(ws));
  Reconstruction model;
  colmap::Image image;  // the sparse model's image
  image.image_id = 4;
  image.name = "sub/a.png";
  model.images[4] = image;
  ExpectError([&] { CheckWorkspaceImages(ws, model); },
              {dir / "w/images/sub/a.png", "image 4", "missing"});
  CreateDirectories(ws.ImagesDir() + "/sub");
  WriteTextFile(ws.ImagePath("sub/a.png"), "");
  EXPECT_NO_THROW(CheckWorkspaceImages(ws, model));
  WriteTextFile(dir / "file", "x");
  ExpectError([&] { CreateDirectories(dir / "file/sub"); },
              {"file/sub", "cannot create"});
}

}  // namespace
}  // namespace fvs::colmap
