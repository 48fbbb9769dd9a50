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
