#include "fvs/util/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "fvs/util/error.h"
#include "support/test_support.h"

namespace fvs {
namespace {

TEST(AtomicFile, WritesAndRenames) {
  testing::TempDir dir;
  const std::string path = dir / "a.txt";
  WriteFileAtomic(path, [](std::ostream& out) { out << "hello"; });
  EXPECT_EQ(ReadFileToString(path), "hello");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(AtomicFile, ExceptionLeavesOldFileAndNoTemp) {
  testing::TempDir dir;
  const std::string path = dir / "a.txt";
  WriteFileAtomic(path, [](std::ostream& out) { out << "old"; });
  EXPECT_THROW(WriteFileAtomic(path,
                               [](std::ostream& out) {
                                 out << "half";
                                 throw std::runtime_error("killed");
                               }),
               std::runtime_error);
  EXPECT_EQ(ReadFileToString(path), "old");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(AtomicFile, UnwritableFolderIsAnError) {
  EXPECT_THROW(WriteFileAtomic("/nonexistent_dir_fvs/x.txt", [](std::ostream&) {}),
               Error);
  EXPECT_THROW(ReadFileToString("/nonexistent_dir_fvs/x.txt"), Error);
}

}  // namespace
}  // namespace fvs
