#include "fvs/util/manifest.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <thread>

#include "support/test_support.h"

namespace fvs {
namespace {

TEST(Manifest, UpToDateOnlyWhenInputsOptionsAndOutputsAgree) {
  testing::TempDir dir;
  const std::string input = dir / "in.txt";
  const std::string output = dir / "out.txt";
  testing::WriteTextFile(input, "a");
  testing::WriteTextFile(output, "b");

  Manifest m = Manifest::Load(dir / "manifest.json");
  const std::string f1 = Manifest::Fingerprint({input}, "opt=1");
  EXPECT_FALSE(m.IsUpToDate("stage", f1, {output}));
  m.Record("stage", f1, {output}, 1.5);
  m.Save();

  Manifest reloaded = Manifest::Load(dir / "manifest.json");
  EXPECT_TRUE(
      reloaded.IsUpToDate("stage", Manifest::Fingerprint({input}, "opt=1"), {output}));
  // Other options.
  EXPECT_FALSE(
      reloaded.IsUpToDate("stage", Manifest::Fingerprint({input}, "opt=2"), {output}));
  // Changed input (size changes, so mtime resolution does not matter).
  testing::WriteTextFile(input, "aa");
  EXPECT_FALSE(
      reloaded.IsUpToDate("stage", Manifest::Fingerprint({input}, "opt=1"), {output}));
  // Missing output.
  testing::WriteTextFile(input, "a");
  const std::string f2 = Manifest::Fingerprint({input}, "opt=1");
  reloaded.Record("stage", f2, {output}, 1.0);
  std::filesystem::remove(output);
  EXPECT_FALSE(reloaded.IsUpToDate("stage", f2, {output}));
}

TEST(Manifest, FolderStampsIgnoreTemporaries) {
  testing::TempDir dir;
  std::filesystem::create_directories(dir / "d/sub");
  testing::WriteTextFile(dir / "d/sub/x.bin", "1");
  const std::string before = StampPaths({dir / "d"});
  testing::WriteTextFile(dir / "d/sub/y.bin.tmp-123-0", "half");
  EXPECT_EQ(StampPaths({dir / "d"}), before);
  testing::WriteTextFile(dir / "d/sub/y.bin", "2");
  EXPECT_NE(StampPaths({dir / "d"}), before);
  EXPECT_NE(StampPaths({dir / "missing"}).find("missing"), std::string::npos);
}

// Outputs and inputs inside the root are recorded relative to it: the folder moved
// elsewhere is still up to date, and the manifest names no absolute path of it.
TEST(Manifest, MovedRootStaysUpToDate) {
  testing::TempDir dir;
  const std::string root = dir / "ws";
  std::filesystem::create_directories(root + "/in");
  testing::WriteTextFile(root + "/in/a.txt", "a");
  testing::WriteTextFile(root + "/out.txt", "b");
  Manifest m = Manifest::Load(root + "/manifest.json", root);
  const std::string f = Manifest::Fingerprint({root + "/in"}, "opt", root);
  m.Record("stage", f, {root + "/out.txt"}, 1.0);
  m.Save();
  EXPECT_EQ(testing::ReadTextFile(root + "/manifest.json").find(dir.path()),
            std::string::npos);

  const std::string moved = dir / "elsewhere";
  std::filesystem::rename(root, moved);
  const Manifest reloaded = Manifest::Load(moved + "/manifest.json", moved);
  EXPECT_EQ(Manifest::Fingerprint({moved + "/in"}, "opt", moved), f);
  EXPECT_TRUE(reloaded.IsUpToDate("stage", f, {moved + "/out.txt"}));
  std::filesystem::remove(moved + "/out.txt");
  EXPECT_FALSE(reloaded.IsUpToDate("stage", f, {moved + "/out.txt"}));
  // Outside the root, paths stay absolute.
  EXPECT_EQ(PathInside("/elsewhere/x", moved), "/elsewhere/x");
  EXPECT_EQ(PathInside(moved + "/a/b", moved), "a/b");
  EXPECT_EQ(PathInside(moved + "x/b", moved), moved + "x/b");
}

// Format 1 recorded absolute outputs: still read, wherever the workspace is now.
TEST(Manifest, ReadsFormatOneWithAbsolutePaths) {
  testing::TempDir dir;
  const std::string root = dir / "now";
  std::filesystem::create_directories(root + "/sfm/0");
  testing::WriteTextFile(root + "/database.db", "x");
  testing::WriteTextFile(root + "/manifest.json",
                         R"({"format": "colmap-fvs manifest 1", "stages": {
    "feature_extraction": {"fingerprint": "f1", "outputs": ["/old/ws/database.db"]},
    "mapping": {"fingerprint": "f2", "outputs": ["/old/ws/sfm/0"], "seconds": 2}}})");
  const Manifest m = Manifest::Load(root + "/manifest.json", root);
  EXPECT_TRUE(m.IsUpToDate("feature_extraction", "f1", {root + "/database.db"}));
  EXPECT_TRUE(m.IsUpToDate("mapping", "f2", {root + "/sfm/0"}));
  EXPECT_FALSE(m.IsUpToDate("mapping", "f1", {root + "/sfm/0"}));
}

TEST(Manifest, CorruptFileMeansRunEverythingAgain) {
  testing::TempDir dir;
  testing::WriteTextFile(dir / "manifest.json", "{\"stages\": {\"a\": 3");
  Manifest m = Manifest::Load(dir / "manifest.json");
  EXPECT_FALSE(m.IsUpToDate("a", "x", {}));
  m.Record("a", "x", {}, 0);
  m.Save();  // replaces the corrupt file
  EXPECT_TRUE(Manifest::Load(dir / "manifest.json").IsUpToDate("a", "x", {}));
}

}  // namespace
}  // namespace fvs
