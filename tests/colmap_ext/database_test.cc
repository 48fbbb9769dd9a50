// database.db written by the real COLMAP (feature_extractor, exhaustive_matcher) read
// back.
#include "colmap_ext/database.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <random>
#include <set>

#include "colmap_ext/camera_models.h"
#include "colmap_ext/image_io.h"
#include "colmap_ext/runner.h"
#include "colmap_ext/workspace.h"
#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs::colmap {
namespace {

using fvs::testing::TempDir;
using fvs::testing::WriteTextFile;

// A textured scene (random blobs) seen with small shifts, so SIFT finds and matches
// points.
void WriteTexturedImages(const std::string& dir, int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0, 1);
  const int w = 160, h = 120;
  fvs::Image world(w + 40, h, 3, 0.5f);
  for (int b = 0; b < 120; ++b) {
    const float cx = uni(rng) * world.width, cy = uni(rng) * h, r = 2 + 5 * uni(rng);
    const float value = uni(rng);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < world.width; ++x)
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r)
          for (int c = 0; c < 3; ++c) world.at(x, y, c) = value;
  }
  for (int i = 0; i < count; ++i) {
    fvs::Image view(w, h, 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) view.at(x, y, c) = world.at(x + 8 * i, y, c);
    WriteImage(dir + "/view" + std::to_string(i) + ".png", view);
  }
}

TEST(Database, ReadsWhatColmapWrote) {
  ::setenv("FVS_COLMAP_BIN", fvs::testing::RealColmapBinary().c_str(), 1);
  ::setenv("FVS_QUIET", "1", 1);
  TempDir dir;
  CreateDirectories(dir / "images");
  WriteTexturedImages(dir / "images", 3);
  const std::string db = dir / "database.db";
  RunColmap({"feature_extractor", "--database_path", db, "--image_path", dir / "images",
             "--ImageReader.camera_model", "OPENCV", "--ImageReader.single_camera", "1",
             "--ImageReader.camera_params", "150.5,151,80,60,0.01,-0.002,0.0003,0.0001",
             "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", "2"});
  DatabaseContents contents = ReadDatabase(db);
  ASSERT_EQ(contents.cameras.size(), 1u);
  const Camera& camera = contents.cameras.begin()->second;
  EXPECT_EQ(camera.model_id, kOpenCV);
  EXPECT_EQ(camera.width, 160u);
  EXPECT_EQ(camera.height, 120u);
  EXPECT_EQ(camera.params,
            (std::vector<double>{150.5, 151, 80, 60, 0.01, -0.002, 0.0003, 0.0001}));
  ASSERT_EQ(contents.images.size(), 3u);
  std::set<std::string> names;
  for (const auto& [id, image] : contents.images) {
    names.insert(image.name);
    EXPECT_EQ(image.camera_id, camera.camera_id);
    EXPECT_GT(image.num_keypoints, 10) << image.name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"view0.png", "view1.png", "view2.png"}));
  EXPECT_EQ(contents.num_matched_pairs, 0);
  for (const auto& [id, image] : contents.images) EXPECT_FALSE(image.has_prior_pose);

  // A pose prior, as a GPS-tagging tool would store it.
  sqlite3* handle = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &handle), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(handle,
                   "UPDATE images SET prior_qw=1, prior_qx=0, prior_qy=0, prior_qz=0, "
                   "prior_tx=1.5, prior_ty=-2, prior_tz=3.25 WHERE name='view1.png'",
                   nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(handle);
  contents = ReadDatabase(db);
  for (const auto& [id, image] : contents.images) {
    EXPECT_EQ(image.has_prior_pose, image.name == "view1.png") << image.name;
    if (image.has_prior_pose) {
      EXPECT_EQ(image.prior_tvec, Eigen::Vector3d(1.5, -2, 3.25));
    }
  }

  RunColmap({"exhaustive_matcher", "--database_path", db, "--SiftMatching.use_gpu", "0",
             "--SiftMatching.num_threads", "2"});
  contents = ReadDatabase(db);
  EXPECT_EQ(contents.num_matched_pairs, 3);  // the views overlap pairwise
  EXPECT_GE(contents.num_verified_pairs, 1);
}

TEST(Database, BadFilesAreNamed) {
  TempDir dir;
  auto expect_error = [](const std::string& path, const std::string& part) {
    try {
      ReadDatabase(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(part), std::string::npos) << message;
    }
  };
  expect_error(dir / "missing.db", "does not exist");
  WriteTextFile(dir / "text.db",
                "this is not an sqlite database, just some text.........\n");
  expect_error(dir / "text.db", "not a COLMAP database");
  WriteTextFile(dir / "empty.db", "");
  expect_error(dir / "empty.db", "no such table");
}

// Ids past uint32 (and keypoint counts past int) are errors, not wrapped onto other
// cameras and images (found reviewing ReadDatabase for tests/fuzz/database_fuzzer).
TEST(Database, OutOfRangeIdsAreErrors) {
  TempDir dir;
  const char* const kSchema =
      "CREATE TABLE cameras (camera_id INTEGER PRIMARY KEY, model INTEGER, width "
      "INTEGER, "
      "height INTEGER, params BLOB, prior_focal_length INTEGER);"
      "CREATE TABLE images (image_id INTEGER PRIMARY KEY, name TEXT, camera_id INTEGER);"
      "CREATE TABLE keypoints (image_id INTEGER PRIMARY KEY, rows INTEGER, cols INTEGER, "
      "data BLOB);"
      "CREATE TABLE matches (pair_id INTEGER PRIMARY KEY, rows INTEGER);"
      "CREATE TABLE two_view_geometries (pair_id INTEGER PRIMARY KEY, rows INTEGER);"
      // SIMPLE_PINHOLE f=8, cx=4, cy=3.
      "INSERT INTO cameras VALUES (1, 0, 8, 6, "
      "X'000000000000204000000000000010400000000000000840', 0);";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"INSERT INTO cameras VALUES (4294967297, 0, 8, 6, "
       "X'000000000000204000000000000010400000000000000840', 0);",
       "camera id 4294967297"},
      {"INSERT INTO images VALUES (4294967297, 'a.png', 1);", "image id 4294967297"},
      {"INSERT INTO images VALUES (1, 'a.png', 4294967297);", "camera id 4294967297"},
      {"INSERT INTO images VALUES (1, 'a.png', 1);"
       "INSERT INTO keypoints VALUES (1, 4294967296, 128, NULL);",
       "keypoint count 4294967296"},
      {"INSERT INTO keypoints VALUES (4294967297, 5, 128, NULL);",
       "image id 4294967297"}};
  int n = 0;
  for (const auto& [rows, fault] : cases) {
    const std::string db = dir / ("ids" + std::to_string(n++) + ".db");
    sqlite3* handle = nullptr;
    ASSERT_EQ(sqlite3_open(db.c_str(), &handle), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(handle, (std::string(kSchema) + rows).c_str(), nullptr,
                           nullptr, nullptr),
              SQLITE_OK)
        << rows;
    sqlite3_close(handle);
    try {
      ReadDatabase(db);
      ADD_FAILURE() << "no error for " << rows;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace fvs::colmap
